#pragma once
// Moving-horizon estimation ([RRM03]; [RM09], ch. 4) over any discrete model
//   x_{i+1} = f(x_i, u_i, i) + w_i,   y_i = h(x_i) + v_i,   w ~ (0, Q), v ~ (0, R):
// at sample k it minimises over the horizon's states z = (x_{k−N+1}, …, x_k)
//   V(z) = ‖x_{k−N+1} − x̄‖²_{P⁻¹} + Σ_{i<k} ‖x_{i+1} − f(x_i, u_i, i)‖²_{Q⁻¹}
//          + Σ_i ‖y_i − h(x_i)‖²_{R⁻¹}          subject to  l ≤ x_i ≤ u,
// and reports x̂_k, the last state. Until k + 1 = N it solves the full-information problem on
// the samples it has, with x̄ = x̄_0 and P = P_0 (MheOptions).
//
// The unknowns are the states, not x_{k−N+1} and the noises w_i: V is then a sum of terms each
// in one state or two neighbours, so the Gauss–Newton matrix is block tridiagonal (solved in
// O(N n³), block_tridiagonal.hpp) however unstable f is, and the bounds on the states — what the
// literature's examples need (concentrations ≥ 0) — are a box. Bounds on w would be nonlinear
// constraints in these unknowns: not offered.
//
// The arrival cost (ArrivalCost, arrival_cost.hpp): when sample j = k − N leaves the horizon,
// x̄ and P become the EKF's prediction from the filtered estimate x̂_{j|j} (the estimate this MHE
// reported at j), the filtering update of [RRM03]. On a linear model this is the Kalman
// filter's prior, and the MHE's estimate is the Kalman filter's at every step for any N (tested
// to 1e-9).
//
// The solver (ProjectedGaussNewton, nlobs/solvers/least_squares/projected_gauss_newton.hpp, its
// stop rules and Summary there): Gauss–Newton on V, its block-tridiagonal linear algebra
// MheHorizonProblem's (horizon_problem.hpp), with a projected backtracking line search and, with
// bounds, the projected Newton method of [Ber82]. Warm start: the previous solution shifted by
// one sample, the new state predicted by the model. real_time_iteration takes one iteration per
// sample ([DBS05]). A step whose V is not finite at the warm start keeps the last estimate. The
// estimate is the lowest V found: a solve cut short (and every real-time iteration) still
// lowered V from the warm start, so it is used (ObserverStep::used_unusable_answer says so).
//
// A sample's outputs may be missing one by one (a non-finite entry): its term weighs the
// measured outputs by the inverse of their own block of R; measurement_missing is set only
// when all are missing.
//
// Samples with times (SampleClock): a gap on the model's grid brings one node per skipped grid
// point, without a measurement (the horizon is N grid points then; while none of its nodes holds
// a measurement the model's prediction is taken without a solve, predict_unmeasured_horizon());
// an interval off the grid is
// one move of the model's flow, its noise weight · Q (weight = interval / T). A sample at the
// last one's instant adds its outputs to that node (one measured there already: failure
// "duplicate_measurement"). A late sample — its time before the last one's — goes into the
// horizon: into the node of its instant, or as a new node between its neighbours (each part of
// their interval made what SampleClock makes of it in order: m grid steps with m − 1 nodes
// without a measurement, or one flow; a fixed-step model refuses one off its grid, "non_uniform"),
// the oldest node leaving if the horizon overflows; then the estimates x̂_{j|j} of the nodes
// from it on are re-solved on the horizon up to each (the arrival cost of later steps
// linearises at them) and the whole horizon is solved. The answer is the one the same samples
// in order give, exactly on a linear model (tested); on a nonlinear one, until the late
// sample leaves the horizon (x̂_{j|j} of the samples after it then come from a horizon that
// starts later than in order). A sample older than the horizon's first is dropped (failure
// "late_measurement_dropped"), counted in late_measurements_dropped() and one warning. Hot path:
// with compile-time sizes nothing is allocated per step except when a sample misses some of its
// outputs.
#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "nlobs/models/model.hpp"
#include "nlobs/observers/core/discrete_jacobians.hpp"
#include "nlobs/observers/core/observer.hpp"
#include "nlobs/observers/core/option_checks.hpp"
#include "nlobs/observers/core/sample_clock.hpp"
#include "nlobs/observers/mhe/arrival_cost.hpp"
#include "nlobs/observers/mhe/horizon_problem.hpp"
#include "nlobs/observers/mhe/mhe_options.hpp"
#include "nlobs/solvers/least_squares/projected_gauss_newton.hpp"
#include "nlobs/solvers/summary.hpp"

namespace nlobs {

template <DiscreteModel Model>
class MheEstimator final : public Observer {
 public:
  static constexpr int kStates = Model::kStates;
  using State = ModelVector<double, Model::kStates>;
  using Input = ModelVector<double, Model::kInputs>;
  using Output = ModelVector<double, Model::kOutputs>;
  using StateMatrix = Eigen::Matrix<double, Model::kStates, Model::kStates>;
  using OutputMatrix = Eigen::Matrix<double, Model::kOutputs, Model::kOutputs>;
  using OutputJacobian = Eigen::Matrix<double, Model::kOutputs, Model::kStates>;

  MheEstimator(Model model, MheOptions options)
      : model_(std::move(model)), options_(detail::validated(std::move(options))) {
    const Eigen::Index n = model_.states(), p = model_.outputs();
    detail::require_size("MheOptions", "initial_estimate", options_.initial_estimate, n);
    if (options_.lower_bounds.size()) {
      detail::require_size("MheOptions", "lower_bounds", options_.lower_bounds, n);
    }
    if (options_.upper_bounds.size()) {
      detail::require_size("MheOptions", "upper_bounds", options_.upper_bounds, n);
    }
    const detail::Covariances c = detail::covariances_of("MheOptions", options_, n, p);
    p0_ = c.initial;
    q_ = c.process;
    r_ = c.measurement;
    q_inv_ = detail::spd_inverse(q_);
    r_inv_ = detail::spd_inverse(r_);
    p0_inv_ = detail::spd_inverse(p0_);
    const double inf = std::numeric_limits<double>::infinity();
    lower_ = options_.lower_bounds.size() ? State(options_.lower_bounds) : State::Constant(n, -inf);
    upper_ = options_.upper_bounds.size() ? State(options_.upper_bounds) : State::Constant(n, inf);
    gauss_newton_ = ProjectedGaussNewton(
        {.max_iterations = options_.real_time_iteration ? 1 : options_.max_iterations,
         .step_tolerance = options_.step_tolerance,
         .cost_tolerance = options_.cost_tolerance});

    const auto h = static_cast<std::size_t>(options_.horizon);
    nodes_.reserve(h + 1);  // a late sample is inserted before the oldest leaves
    problem_.emplace(q_inv_, lower_, upper_, h, n, p);
    chain_states_.assign(h, State::Zero(n));
    missing_ = Eigen::VectorXd::Constant(p, kMissing);

    info_.name = options_.name;
    info_.engine = ProjectedGaussNewton::kName;
    info_.signals = {{"cost", SignalKind::kDiagnostic}};
    step_.signals = Eigen::VectorXd::Zero(1);
    reset();
  }

  void reset() override {
    nodes_.clear();
    clock_.reset();
    arrival_.reset(options_.initial_estimate, p0_, p0_inv_);
    estimate_ = arrival_.mean();
    late_dropped_ = 0;
    chain_ = false;
    info_.warnings.clear();
  }

  const ObserverStep& step(long k, double t, const Eigen::VectorXd& y,
                           const Eigen::VectorXd& u) override {
    require_sample_sizes(name(), k, y, u, model_.outputs(), model_.inputs());
    step_.failure.clear();
    step_.failure_message.clear();
    step_.measurement_missing = !y.array().isFinite().any();
    step_.summary.reset();
    step_.used_unusable_answer = false;
    if (!nodes_.empty() && std::isfinite(t) && t < clock_.time() - same_instant()) {
      late(k, t, y, u);
    } else if (clock_.place(name(), k, t, step_)) {
      if (clock_.moves() == 0 && !nodes_.empty()) {  // a second sample of the last instant
        if (merge(nodes_.size() - 1, k, t, y)) {
          clock_.commit();
          report(solve(k, nodes_.size()));
        }
      } else {
        // One node per move: a gap on the model's grid brings nodes without a measurement.
        const long moves = std::max(1L, clock_.moves());
        for (long j = 0; j < moves; ++j) {
          const auto move = clock_.moves() ? std::optional(clock_.move(j)) : std::nullopt;
          if (j + 1 < moves) {
            append(k, move, t, missing_, Eigen::VectorXd(nodes_.back().u));
            if (predict_unmeasured_horizon()) continue;
          } else {
            append(k, move, t, y, u);
          }
          report(solve(k, nodes_.size()));
        }
        clock_.commit();
      }
    }
    step_.estimate = estimate_;
    return step_;
  }

  // Late measurements older than the horizon's first sample, dropped since reset() (each a step
  // with failure "late_measurement_dropped", and counted in one of info().warnings).
  long late_measurements_dropped() const { return late_dropped_; }

  // The arrival cost's x̄ and P (the prior on the horizon's first state).
  const State& arrival_mean() const { return arrival_.mean(); }
  const StateMatrix& arrival_covariance() const { return arrival_.covariance(); }
  // The horizon's estimates x̂_{k−M+1|k}, …, x̂_{k|k} (M ≤ N samples so far), oldest first, one
  // per column.
  Eigen::MatrixXd horizon_estimates() const {
    Eigen::MatrixXd out(model_.states(), static_cast<Eigen::Index>(nodes_.size()));
    for (std::size_t i = 0; i < nodes_.size(); ++i)
      out.col(static_cast<Eigen::Index>(i)) = nodes_[i].x;
    return out;
  }

 private:
  using Node = MheNode<Model>;
  static constexpr double kMissing = std::numeric_limits<double>::quiet_NaN();
  // The longest part of an interval a late sample may split into grid steps (each a node), in
  // sample times: beyond it the late sample is dropped, so that its cost stays bounded.
  static constexpr double kLongestLateSplit = 1e4;

  // "The same instant" for sample times: within the rounding of recorded times.
  double same_instant() const {
    const double step = clock_.sample_time();
    return step > 0.0 ? SampleClock::tolerance(std::abs(clock_.time()), step) * step : 0.0;
  }

  // The node's y, mask and R⁻¹ from y (non-finite entries: not measured).
  void set_measurement(Node& node, const Eigen::VectorXd& y) const {
    const Eigen::Index p = model_.outputs();
    const auto present = y.array().isFinite();
    node.y = Output(present.select(y.array(), 0.0).matrix());
    node.measured = Output(present.template cast<double>().matrix());
    if (present.all()) {
      node.r_inv = r_inv_;
      return;
    }
    node.r_inv = OutputMatrix::Zero(p, p);
    const std::vector<Eigen::Index> rows = measured_outputs(y);
    if (rows.empty()) return;
    const Eigen::MatrixXd r_measured = r_(rows, rows);
    const Eigen::MatrixXd inv = detail::spd_inverse(r_measured);
    node.r_inv(rows, rows) = inv;
  }

  // Sample k's outputs into node i of the same instant; false (the step's failure
  // "duplicate_measurement") when one of them was measured there already.
  bool merge(std::size_t i, long k, double t, const Eigen::VectorXd& y) {
    Node& node = nodes_[i];
    Eigen::VectorXd merged = node.y;
    for (Eigen::Index c = 0; c < y.size(); ++c) {
      if (!(node.measured[c] > 0.0)) merged[c] = kMissing;
    }
    for (Eigen::Index c = 0; c < y.size(); ++c) {
      if (!std::isfinite(y[c])) continue;
      if (node.measured[c] > 0.0) {
        std::ostringstream os;
        os << name() << ": sample k = " << k << " at t = " << t << " measures output " << c + 1
           << ", which the sample at t = " << node.t << " (k = " << node.k
           << ") measured already; ignored";
        step_.failure = "duplicate_measurement";
        step_.failure_message = os.str();
        return false;
      }
      merged[c] = y[c];
    }
    set_measurement(node, merged);
    return true;
  }

  // A new last node at the end of `move` (the first sample: none) holding y and u; the oldest
  // leaves when the horizon is full.
  void append(long k, const std::optional<ModelStep>& move, double t, const Eigen::VectorXd& y,
              const Eigen::VectorXd& u) {
    State guess = arrival_.mean();
    if (move) {
      Node& last = nodes_.back();
      last.next = *move;
      guess = advance(model_, last.x, last.u, *move);
      if (!guess.allFinite()) guess = last.x;
      t = move->time + move->length;
    }
    if (nodes_.size() == static_cast<std::size_t>(options_.horizon)) {
      drop_oldest(k);
      std::rotate(nodes_.begin(), nodes_.begin() + 1, nodes_.end());
    } else {
      nodes_.emplace_back();
    }
    Node& node = nodes_.back();
    node.k = k;
    node.t = t;
    node.u = Input(u);
    node.next = ModelStep{};
    set_measurement(node, y);
    node.x = guess.cwiseMax(lower_).cwiseMin(upper_);
  }

  // A sample older than the last one: merged into the node of its instant, or inserted between
  // its neighbours (the model's flow over the two parts of their interval), and the horizon
  // re-solved; older than the horizon, dropped and counted.
  void late(long k, double t, const Eigen::VectorXd& y, const Eigen::VectorXd& u) {
    const double tolerance = same_instant();
    std::ostringstream os;
    os << name() << ": the late sample k = " << k << " at t = " << t;
    if (t < nodes_.front().t - tolerance) {
      ++late_dropped_;
      os << " is older than the horizon's first sample (t = " << nodes_.front().t << "); dropped";
      step_.failure = "late_measurement_dropped";
      step_.failure_message = os.str();
      std::ostringstream warning;
      warning << late_dropped_ << " late measurement(s) older than the horizon dropped (the "
              << "first: " << (late_dropped_ == 1 ? os.str() : first_late_) << ")";
      if (late_dropped_ == 1) {
        first_late_ = os.str();
        info_.warnings.push_back(warning.str());
      } else {
        info_.warnings.back() = warning.str();
      }
      return;
    }
    std::size_t i = 0;
    while (i + 1 < nodes_.size() && nodes_[i + 1].t <= t + tolerance) ++i;
    std::size_t from = i;
    if (std::abs(nodes_[i].t - t) <= tolerance) {
      if (!merge(i, k, t, y)) return;
    } else {
      if (!has_interval_flow(model_)) {
        os << " falls between the samples at t = " << nodes_[i].t << " and " << nodes_[i + 1].t
           << "; the model has a fixed step (no flow over an interval): refused";
        step_.failure = "non_uniform";
        step_.failure_message = os.str();
        return;
      }
      if (!insert_after(i, k, t, y, u)) {
        os << " would split an interval of more than " << kLongestLateSplit
           << " sample times into grid steps; dropped";
        step_.failure = "late_measurement_dropped";
        step_.failure_message = os.str();
        return;
      }
      from = i + 1;
    }
    // The samples from the late one on are taken again as in order: each x̂_{j|j} re-solved on
    // the horizon up to it (what the arrival cost of later steps linearises at), the oldest
    // leaving first whenever that horizon would exceed N; the last is the step's answer.
    const auto horizon = static_cast<std::size_t>(options_.horizon);
    for (std::size_t j = from; j < nodes_.size(); ++j) {
      for (; j + 1 > horizon; --j) {
        drop_oldest(k);
        nodes_.erase(nodes_.begin());
      }
      if (j + 1 == nodes_.size()) {
        report(solve(k, j + 1));
        break;
      }
      const Summary replay = solve(k, j + 1);
      if (replay.status != Status::kNonFinite) nodes_[j].filtered = nodes_[j].x;
    }
  }

  // A node at t between nodes i and i + 1: each part of the interval between them is what
  // SampleClock makes of it in order — a multiple m of T is m steps (with m − 1 nodes without a
  // measurement between), any other length one flow.
  // False (nothing inserted) when a part would bring more than kLongestLateSplit grid steps.
  bool insert_after(std::size_t i, long k, double t, const Eigen::VectorXd& y,
                    const Eigen::VectorXd& u) {
    const double step = clock_.sample_time();
    for (const double length : {t - nodes_[i].t, nodes_[i + 1].t - t}) {
      if (length / step > kLongestLateSplit) return false;
    }
    std::vector<Node> inserted;
    // Nodes without a measurement at the grid points strictly between `from` and `to` when
    // to − from is a multiple m ≥ 2 of T (input `held` over them).
    auto part = [&](double from, double to, const Input& held) {
      const double length = to - from;
      const double m = std::round(length / step);
      if (m >= 2.0 && std::abs(length / step - m) <= SampleClock::tolerance(std::abs(to), step)) {
        for (long j = 1; j < static_cast<long>(m); ++j) {
          Node gap;
          gap.k = k;
          gap.t = from + static_cast<double>(j) * step;
          gap.u = held;
          set_measurement(gap, missing_);
          inserted.push_back(gap);
        }
      }
    };
    part(nodes_[i].t, t, nodes_[i].u);
    Node node;
    node.k = k;
    node.t = t;
    node.u = Input(u);
    set_measurement(node, y);
    inserted.push_back(node);
    part(t, nodes_[i + 1].t, node.u);
    // The moves: from each node to the next, over what lies between them.
    const auto flow = [step](double from, double to) {
      ModelStep s;
      s.flow = true;
      s.time = from;
      s.length = to - from;
      s.weight = s.length / step;
      return s;
    };
    const auto is_grid_step = [step](double length) {
      return std::abs(length / step - 1.0) <= SampleClock::tolerance(length, step);
    };
    Node* previous = &nodes_[i];
    for (Node& n : inserted) {
      previous->next = flow(previous->t, n.t);
      if (is_grid_step(previous->next.length)) previous->next.weight = 1.0;
      const State guess = advance(model_, previous->x, previous->u, previous->next);
      n.x = (guess.allFinite() ? guess : previous->x).cwiseMax(lower_).cwiseMin(upper_);
      n.filtered = n.x;
      previous = &n;
    }
    previous->next = flow(previous->t, nodes_[i + 1].t);
    if (is_grid_step(previous->next.length)) previous->next.weight = 1.0;
    nodes_.insert(nodes_.begin() + static_cast<std::ptrdiff_t>(i + 1), inserted.begin(),
                  inserted.end());
    return true;
  }

  // The step's estimate, summary and signal from the solve of the whole horizon.
  void report(Summary summary) {
    if (summary.status != Status::kNonFinite) estimate_ = nodes_.back().x;
    summary.record_answer(estimate_, StopCriteria{}, true);
    step_.used_unusable_answer = summary.status != Status::kNonFinite && !summary.usable();
    step_.signals[0] = summary.objective.value_or(std::numeric_limits<double>::quiet_NaN());
    step_.summary = std::move(summary);
    nodes_.back().filtered = estimate_;
  }

  // A node of a gap while no node of the horizon holds a measurement: V's minimiser is then the
  // model's prediction from x̄ (V = 0 there) whenever it stays in the bounds and the domain, and
  // Gauss–Newton from the warm start would stop at it after one linearisation. It is taken
  // without a solve, so that a gap of m grid steps costs m arrival-cost updates (an EKF's
  // predictions) instead of m solves of the horizon. The chain is extended by its last node
  // while x̄ is the first node's state (the nodes before it came from the same chain), rebuilt
  // otherwise. False (nothing changed) when it does not apply.
  bool predict_unmeasured_horizon() {
    for (const Node& node : nodes_) {
      if ((node.measured.array() > 0.0).any()) return false;
    }
    const auto usable = [this](const State& x) {
      return x.allFinite() && (x.array() >= lower_.array()).all() &&
             (x.array() <= upper_.array()).all() && inside_domain(x);
    };
    const std::size_t m = nodes_.size();
    const std::size_t first = chain_ && nodes_.front().x == arrival_.mean() ? m - 1 : 0;
    for (std::size_t i = first; i < m; ++i) {
      chain_states_[i] = i == 0
                             ? arrival_.mean()
                             : advance(model_, i == first ? nodes_[i - 1].x : chain_states_[i - 1],
                                       nodes_[i - 1].u, nodes_[i - 1].next);
      if (!usable(chain_states_[i])) {
        chain_ = false;
        return false;
      }
    }
    for (std::size_t i = first; i < m; ++i) nodes_[i].x = chain_states_[i];
    chain_ = true;
    Summary summary;
    summary.engine = ProjectedGaussNewton::kName;
    summary.status = Status::kConverged;
    summary.objective = 0.0;
    summary.residual_norm = 0.0;
    summary.step_norm = 0.0;
    summary.function_evaluations = static_cast<int>(m - first);
    summary.message = "no measurement in the horizon: the model's prediction from the prior";
    report(std::move(summary));
    return true;
  }

  // The filtering update of the arrival cost along the sample that leaves the horizon.
  void drop_oldest(long k) {
    const Node& old = nodes_.front();
    if (!arrival_.update(model_, old.filtered, old.u, old.next, (old.measured.array() > 0.0).any(),
                         old.r_inv, q_)) {
      std::ostringstream os;
      os << name() << ": the arrival cost's update along sample k = " << old.k << " (at k = " << k
         << ") is not finite or not positive definite; x̄ and P kept";
      mark_non_finite_estimate(step_, os.str());
    }
  }

  bool inside_domain(const State& x) const { return domain_violation_of(model_, x).empty(); }

  // Minimises V over the first m nodes (their states left at the answer) and returns the
  // Summary, V in its objective; a V not finite at the warm start marks the step.
  Summary solve(long k, std::size_t m) {
    chain_ = false;
    problem_->bind(model_, nodes_, m, arrival_);
    Summary summary = gauss_newton_.minimise(*problem_);
    if (summary.status == Status::kNonFinite) {
      std::ostringstream os;
      os << name() << ": the cost V at sample k = " << k << " is not finite at the warm start "
         << "(the model overflows or leaves its domain); kept the last estimate";
      mark_non_finite_estimate(step_, os.str());
      summary.message = step_.failure_message;
    }
    return summary;
  }

  Model model_;
  MheOptions options_;
  StateMatrix p0_, p0_inv_, q_, q_inv_;
  OutputMatrix r_, r_inv_;
  State lower_, upper_;
  ProjectedGaussNewton gauss_newton_;
  ArrivalCost<Model> arrival_;
  State estimate_;
  std::vector<Node> nodes_;  // the horizon's samples, oldest first
  // V over the horizon's nodes and its Gauss–Newton algebra (horizon_problem.hpp).
  std::optional<MheHorizonProblem<Model>> problem_;
  std::vector<State> chain_states_;  // predict_unmeasured_horizon()'s prediction chain
  // The nodes' states are the model's prediction chain from x̄ (predict_unmeasured_horizon()).
  bool chain_ = false;
  SampleClock clock_ = SampleClock::of(model_, "", true);
  Eigen::VectorXd missing_;  // y of a gap's node: no output measured
  long late_dropped_ = 0;
  std::string first_late_;  // the first late measurement dropped, for the warning
  ObserverStep step_;
};

}  // namespace nlobs
