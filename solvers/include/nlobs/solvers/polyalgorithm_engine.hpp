#pragma once
// A polyalgorithm: engines tried in order within one evaluation budget, each from the start or
// from the best point so far (smallest ‖F‖∞), until one returns a usable answer
// (Summary::usable()). The registry's `auto` is this with the stages of kAutoOrder
// (below), the order measured on the MGH set (docs/solvers.md). Summary::stage names
// the engine whose answer is returned; Summary::message lists how every stage before it ended (a
// stage that throws, whatever it throws, is one of them; when every stage that ran threw, the
// first stage's exception is rethrown unchanged, so that a user's F that throws wherever it is
// evaluated reaches the caller as it does from any other engine). The budget is shared through
// Engine::limit_evaluations: a stage that ignores it ends the run after it.
#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "nlobs/common/printable.hpp"
#include "nlobs/solvers/engine.hpp"
#include "nlobs/solvers/engine_spec.hpp"

namespace nlobs {

// The stages of the registry's `auto`, in order, each from x0: Newton first (the cheapest when it
// works), the dogleg where its full steps fail, Levenberg-Marquardt where the dogleg stagnates,
// the pseudo-transient flow last. Measured on the MGH set against other orders (docs/solvers.md).
inline constexpr const char* kAutoOrder = "newton/dogleg/levenberg-marquardt/pseudo-transient";

struct PolyalgorithmOptions {
  // true: a stage starts where the stages before it left the smallest ‖F‖∞; false (default):
  // every stage starts from the caller's x0. Measured on the MGH set, a stage that stagnated
  // often leaves its best point at a local minimum of ‖F‖ that traps the next one (auto solves
  // 52 of 57 runs from the best point, 53 from the start).
  bool restart_from_best = false;
  // Stop with Status::kLocalMinimum once this many stages ended, none usable (stagnated, at the
  // rounding floor or blocked by a bound), at the same point with the same ‖F‖∞: within
  // kSameMinimum relative, ‖x − x'‖∞ ≤ kSameMinimum · max(1, ‖x'‖∞) and
  // |‖F‖ − ‖F'‖| ≤ kSameMinimum · max(‖F‖, ‖F'‖). Different methods from x0 that meet at one
  // point have found a local minimum of ‖F‖ they cannot leave; the stages after them are not run.
  // 0 = never: every stage runs until one is usable or the budget is spent.
  int shared_minimum = 2;
  static constexpr double kSameMinimum = 1e-3;
  // On a problem with a sparse Jacobian (declared, or detected at x0) of more than this many
  // unknowns, the stages without a sparse path (Engine::has_sparse_path: dogleg, newton's trust
  // region, …) are not run: each would build and factor a dense n×n J — at n = 10⁴ 800 MB and
  // minutes per factorisation, where newton and pseudo-transient take milliseconds on the
  // sparse path — unless no stage has a sparse path (auto:order=dogleg):
  // then all run, densely. 0: run them at any n. ≥ 0.
  Index dense_stage_limit = 1000;

  // Throws InvalidInput naming the field, its value and the requirement (options_validation.hpp).
  void validate() const;
  // The registry's `auto` (its stages by `order`, kAutoOrder by default), the spec keys and
  // their reading over these values; `order` is read by the registry entry, which builds the
  // stages (src/options/polyalgorithm_options.cpp).
  static EngineDescription describe();
  void read(EngineSpecReader& spec);
};

template <int N = Dynamic>
class PolyalgorithmEngine : public Engine<N> {
 public:
  // `stages` run in this order; each gets the evaluations (SolverOptions::stop.max_evaluations
  // of this engine) that the stages before it left. At least one stage, none null.
  PolyalgorithmEngine(std::vector<std::unique_ptr<Engine<N>>> stages,
                      PolyalgorithmOptions poly = {}, SolverOptions options = {})
      : Engine<N>(std::move(options)), stages_(std::move(stages)), poly_(poly) {
    poly_.validate();
    if (stages_.empty()) throw InvalidInput("auto: needs at least one engine to try");
    for (const auto& s : stages_) {
      if (!s) throw InvalidInput("auto: a stage engine is null");
      caps_.push_back(s->options().stop.max_evaluations);  // a stage's own cap stays a cap
    }
  }

  std::string_view name() const override { return "auto"; }
  const std::vector<std::unique_ptr<Engine<N>>>& stages() const { return stages_; }
  // Bounds reach every stage: accepted when every stage accepts them.
  bool accepts_bounds() const override {
    return std::all_of(stages_.begin(), stages_.end(),
                       [](const auto& s) { return s->accepts_bounds(); });
  }
  bool accepts_strict_bounds() const override {
    return std::all_of(stages_.begin(), stages_.end(),
                       [](const auto& s) { return s->accepts_strict_bounds(); });
  }

  // A scaling reaches every stage (each solves in the scaled variables; the stages' residuals,
  // which auto compares, are then all ‖D_f F‖∞): accepted when every stage accepts one.
  bool accepts_scaling() const override {
    return std::all_of(stages_.begin(), stages_.end(),
                       [](const auto& s) { return s->accepts_scaling(); });
  }
  bool has_sparse_path() const override {
    return std::any_of(stages_.begin(), stages_.end(),
                       [](const auto& s) { return s->has_sparse_path(); });
  }

  Summary solve(const FixedPointProblem<N>& problem, Vector<N>& x) override {
    detail::check_initial_guess(name(), problem, x);
    const int budget = this->options_.stop.max_evaluations;
    const Vector<N> start = x;
    Vector<N> best = x, trial = x;
    double best_residual = std::numeric_limits<double>::infinity();
    Summary best_summary, last;
    bool have_best = false, have_last = false;
    std::exception_ptr first_throw;  // null unless a stage threw: nothing allocated otherwise
    // Where the stages that stopped without progress ended (PolyalgorithmOptions::shared_minimum).
    std::vector<Vector<N>> ends;
    std::vector<double> end_residuals;
    std::vector<std::string> end_labels;
    std::vector<Status> end_statuses;
    bool shared = false, stopped_by_callback = false;
    int evaluations = 0, jacobians = 0, iterations = 0;
    std::ostringstream history;
    auto note = [&history](const std::string& what) {
      if (history.tellp() > 0) history << "; ";
      history << what;
    };
    // The stages skipped on a large sparse problem are noted when the run reaches them (a stage
    // before them that succeeds leaves no note).
    const std::vector<bool> run = stages_to_run(problem, x);
    std::string skipped;
    auto note_skipped = [&] {
      if (skipped.empty()) return;
      note(skipped + " not run (no sparse path, and n = " + std::to_string(x.size()) +
           " > dense_stage_limit " + std::to_string(poly_.dense_stage_limit) + ")");
      skipped.clear();
    };
    for (std::size_t k = 0; k < stages_.size(); ++k) {
      Engine<N>& stage = *stages_[k];
      if (!run[k]) {
        skipped += (skipped.empty() ? "" : ", ") + stage.label();
        continue;
      }
      note_skipped();
      const int left = budget - evaluations;
      if (left < 1) break;
      stage.limit_evaluations(std::min(left, caps_[k]));
      trial = poly_.restart_from_best && have_best ? best : start;
      try {
        last = stage.solve(problem, trial);
      } catch (...) {  // a stage's failure, whatever it threw, is a row of the history
        if (!first_throw) first_throw = std::current_exception();
        note(stage.label() + " threw: " + current_exception_text());
        continue;
      }
      have_last = true;
      // A user's engine may not record its answer; judge it by the point it returned.
      if (!last.answer_recorded) last.record_answer(trial, stage.options().stop);
      evaluations += last.function_evaluations;
      jacobians += last.jacobian_evaluations;
      iterations += last.iterations;
      last.stage = stage.label();
      if (last.usable()) {
        best = trial;
        best_summary = std::move(last);
        have_best = true;
        break;
      }
      std::string what = stage.label() + " " + std::string(to_string(last.status));
      if (!last.message.empty()) what += " (" + last.message + ")";
      note(what);
      // The best point so far: finite, with the smallest residual any stage returned.
      if (trial.allFinite() && last.residual_norm < best_residual) {
        best_residual = last.residual_norm;
        best = trial;
        best_summary = last;
        have_best = true;
      }
      // The user's iteration callback (each stage has it, from the registry) ends the whole run.
      if (last.status == Status::kStoppedByCallback) {
        stopped_by_callback = true;
        if (trial.allFinite()) {  // the answer is where the callback stopped, not the best point
          best = trial;
          best_summary = last;
          have_best = true;
        }
        break;
      }
      if (last.function_evaluations > left) break;  // a stage that ignored its limit
      if (poly_.shared_minimum > 0 && stopped_without_progress(last.status) && trial.allFinite() &&
          std::isfinite(last.residual_norm)) {
        int meeting = 1;
        bool all_blocked = last.status == Status::kBlockedByBound;
        std::string met;
        for (std::size_t j = 0; j < ends.size(); ++j) {
          if (!same_minimum(trial, last.residual_norm, ends[j], end_residuals[j])) continue;
          ++meeting;
          all_blocked = all_blocked && end_statuses[j] == Status::kBlockedByBound;
          met += (met.empty() ? "" : ", ") + end_labels[j];
        }
        if (meeting >= poly_.shared_minimum) {
          std::ostringstream os;
          os.precision(3);
          os << stage.label() << " ended";
          if (!met.empty()) os << " where " << met << " did";
          os << " (|F| " << std::scientific << last.residual_norm
             << "): a local minimum of |F| that is not a root";
          if (k + 1 < stages_.size()) {
            os << "; not run:";
            for (std::size_t j = k + 1; j < stages_.size(); ++j) {
              os << (j == k + 1 ? " " : ", ") << stages_[j]->label();
            }
          }
          note(os.str());
          // The answer is the best point. When it is the meeting point, its status says why the
          // run ended there: local_minimum, or blocked_by_bound when every stage that met there
          // was held by a bound (the history names the component). A better point another stage
          // left keeps that stage's own status: its failure is not this minimum's.
          if (same_minimum(best, best_residual, trial, last.residual_norm)) {
            best_summary.status = all_blocked ? Status::kBlockedByBound : Status::kLocalMinimum;
          }
          shared = true;
          break;
        }
        ends.push_back(trial);
        end_residuals.push_back(last.residual_norm);
        end_labels.push_back(stage.label());
        end_statuses.push_back(last.status);
      }
    }
    note_skipped();
    Summary s;
    if (have_best) {
      s = std::move(best_summary);
      x = best;
    } else if (have_last) {
      // No stage left a point with a known residual: the last stage's point, if finite.
      s = std::move(last);
      if (trial.allFinite()) {
        x = trial;
      } else {
        x = start;
        s.residual_norm = std::numeric_limits<double>::quiet_NaN();
        s.step_norm = 0.0;
        s.trace.clear();
      }
    } else if (first_throw) {
      // Every stage that ran threw: most likely the user's F or Jacobian, which the caller must
      // see as from any engine (a cancellation, a domain error), not as a solver failure.
      x = start;
      std::rethrow_exception(first_throw);
    } else {  // no stage ran (an empty budget)
      x = start;
      s.status = Status::kSolverFailure;
    }
    const bool usable = s.usable();
    std::string before = history.str();
    if (!usable && !shared && evaluations >= budget) {
      before += (before.empty() ? "" : "; ") + std::string("the evaluation budget (") +
                std::to_string(budget) + ") is spent";
    }
    if (!before.empty()) s.message = usable ? "after " + before : before;
    if (stopped_by_callback) s.status = Status::kStoppedByCallback;
    s.engine = name();
    s.function_evaluations = evaluations;
    s.jacobian_evaluations = jacobians;
    s.iterations = iterations;
    s.record_answer(x, this->options_.stop, s.residual_minimised);
    return s;
  }

 private:
  // Every stage, but those without a sparse path on a problem with a sparse Jacobian larger than
  // dense_stage_limit (detected here, at x, if that is still to do) — unless no stage with one
  // would be left, when all run, densely, as before the sparse path existed.
  std::vector<bool> stages_to_run(const FixedPointProblem<N>& problem, const Vector<N>& x) const {
    std::vector<bool> run(stages_.size(), true);
    if constexpr (N == Dynamic) {
      const bool any_sparse = std::any_of(stages_.begin(), stages_.end(),
                                          [](const auto& s) { return s->has_sparse_path(); });
      if (!any_sparse || poly_.dense_stage_limit == 0 || x.size() <= poly_.dense_stage_limit ||
          problem.sparse_residual_jacobian(x) == nullptr) {
        return run;
      }
      for (std::size_t k = 0; k < stages_.size(); ++k) run[k] = stages_[k]->has_sparse_path();
    } else {
      static_cast<void>(problem), static_cast<void>(x);
    }
    return run;
  }
  static bool stopped_without_progress(Status status) {
    return status == Status::kStagnated || status == Status::kRoundingFloor ||
           status == Status::kBlockedByBound;
  }
  static bool same_minimum(const Vector<N>& x, double residual, const Vector<N>& y, double other) {
    const double tol = PolyalgorithmOptions::kSameMinimum;
    const double scale = std::max(1.0, y.template lpNorm<Eigen::Infinity>());
    return (x - y).template lpNorm<Eigen::Infinity>() <= tol * scale &&
           std::abs(residual - other) <= tol * std::max(residual, other);
  }
  // Every stage takes the box (the scaling), or none does: a stage that refuses it
  // (levenberg-marquardt with geodesic acceleration refuses a box) puts the stages before it
  // back to their own, read through `get`.
  template <typename T, typename Get, typename Set>
  void set_on_every_stage(const T& value, Get get, Set set) {
    std::vector<T> previous;
    for (const auto& s : stages_) previous.push_back(((*s).*get)());
    std::size_t k = 0;
    try {
      for (; k < stages_.size(); ++k) ((*stages_[k]).*set)(value);
    } catch (...) {
      for (std::size_t j = 0; j < k; ++j) ((*stages_[j]).*set)(previous[j]);
      throw;
    }
  }
  void on_set_bounds() override {
    set_on_every_stage(this->bounds_, &Engine<N>::bounds, &Engine<N>::set_bounds);
  }
  void on_set_scaling() override {
    set_on_every_stage(this->scaling_, &Engine<N>::scaling, &Engine<N>::set_scaling);
  }
  void on_set_record_trace(bool on) override {
    for (const auto& s : stages_) s->set_record_trace(on);  // (it cannot fail)
  }
  std::vector<std::unique_ptr<Engine<N>>> stages_;
  std::vector<int> caps_;
  PolyalgorithmOptions poly_;
};

}  // namespace nlobs
