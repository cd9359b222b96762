#pragma once
// F(x) = G(x) − x and J_F = ∂G − I of a fixed-point problem, for the engines that solve it as a
// square root problem (Newton, dogleg, Broyden, pseudo-transient; Levenberg–Marquardt, whose F
// may be m×n, keeps its accounts in the same SolveLedger): the one place that counts
// evaluations, checks G's size, keeps a difference Jacobian inside the evaluation budget and the
// box, and fills the Summary at the end.
#include <algorithm>
#include <limits>
#include <optional>
#include <string>

#include "nlobs/solvers/box_bounds.hpp"
#include "nlobs/solvers/engine.hpp"
#include "nlobs/solvers/finite_difference.hpp"
#include "nlobs/solvers/line_search.hpp"
#include "nlobs/solvers/linear/linear_solver.hpp"
#include "nlobs/solvers/sparse/sparsity_pattern.hpp"
#include "nlobs/solvers/stop_monitor.hpp"

namespace nlobs::detail {

// jac = J_F(x) by the state's source (resolved), f = F(x); returns the evaluations of F it made.
// A J of another structure than the source's pattern (a user's evaluate) is refused: the engines
// address its entries through the pattern.
inline int evaluate_sparse_jacobian(SparseJacobianState& state, const Vector<Dynamic>& x,
                                    const Vector<Dynamic>& f, SparseJacobian& jac) {
  const int spent = state.evaluate(x, f, jac);
  const SparsityPattern& pattern = *state.get()->pattern;
  if (jac.rows() != pattern.rows || jac.cols() != pattern.cols || !jac.isCompressed() ||
      jac.nonZeros() != pattern.nonzeros()) {
    throw InvalidInput(
        "the sparse Jacobian's evaluate returned a " + std::to_string(jac.rows()) + "x" +
        std::to_string(jac.cols()) + " matrix with " + std::to_string(jac.nonZeros()) +
        " stored entries" + (jac.isCompressed() ? "" : " (not compressed)") +
        ", not the structure of its pattern (" + std::to_string(pattern.rows) + "x" +
        std::to_string(pattern.cols) + ", " + std::to_string(pattern.nonzeros()) + " entries)");
  }
  return spent;
}

// x0 already solves F: ‖F(x0)‖₂ = 0, or StopCriteria's residual criterion holds there.
template <int N>
bool solved_at_start(const Vector<N>& f, const StopCriteria& stop) {
  const double largest = f.template lpNorm<Eigen::Infinity>();
  return largest == 0.0 || (stop.residual_tolerance && largest <= *stop.residual_tolerance);
}

// The accounts of one run of an engine on F, square or m×n (the SquareSystem engines,
// Levenberg–Marquardt's least squares): evaluations and Jacobians against
// StopCriteria::max_evaluations, the progress window, the box, and the Summary they end in.
template <int N>
class SolveLedger {
 public:
  // A new run from x0 (checked inside `bounds`): nothing counted yet. stop: its max_evaluations,
  // progress_window (none when !progress_window: a least-squares minimum has ‖F‖ > 0 and a warm
  // start may sit at it), and what makes ‖F‖∞ usable.
  void start(std::string_view engine, const BoxBounds& bounds, const Vector<N>& x0,
             const StopCriteria& stop, bool progress_window = true) {
    box_.start(engine, bounds, x0);
    max_evaluations_ = stop.max_evaluations;
    usable_residual_ = std::max(stop.residual_tolerance.value_or(0.0), stop.acceptance_tolerance);
    progress_.start(progress_window ? stop.progress_window : 0);
    evaluations_ = jacobians_ = 0;
  }

  // For an evaluation of F at a point of the path, ‖F‖₂ there (inf when F is not finite; a
  // probe that is no point of the path, such as a second difference, passes inf: counted, never
  // progress).
  void count_evaluation(double residual_norm) {
    ++evaluations_;
    progress_.saw(residual_norm);
  }
  // After a Jacobian that spent `evaluations` of F (differences; 0 when the problem has one).
  void count_jacobian(int evaluations) {
    evaluations_ += evaluations;
    ++jacobians_;
  }
  // `evaluations` more stay within the budget.
  bool affords(int evaluations) const { return evaluations_ + evaluations <= max_evaluations_; }

  // The evaluation budget is spent, or the progress window has passed without progress: the run
  // ends with spent_status().
  bool budget_spent() const { return evaluations_ >= max_evaluations_ || progress_.expired(); }
  // Why budget_spent(): kMaxEvaluations, or kStagnated with `message` set.
  Status spent_status(std::string& message) const {
    if (evaluations_ >= max_evaluations_) return Status::kMaxEvaluations;
    message = progress_.message();
    return Status::kStagnated;
  }
  // As above, where a window that expired with the box holding x against `descent` (−∇(½‖F‖²)
  // at the engine's last Jacobian) is kBlockedByBound: out of progress because a bound stops x,
  // the diagnosis the engine's own stuck tests would have given — unless ‖F‖∞ (residual_norm) is
  // already small enough to use: a stagnated answer is usable there, a blocked one never.
  Status spent_status(std::string& message, const Vector<N>& x, const Vector<N>& descent,
                      double residual_norm) const {
    const Status spent = spent_status(message);
    if (spent != Status::kStagnated || !box_.active() || residual_norm <= usable_residual_) {
      return spent;
    }
    if (const std::optional<Index> i = box_.blocking(x, descent, BoxMove::kDirection)) {
      message = box_.blocked_message(*i, x, residual_norm, "the descent direction");
      return Status::kBlockedByBound;
    }
    return spent;
  }
  int evaluations() const { return evaluations_; }
  int jacobians() const { return jacobians_; }
  const Box<N>& box() const { return box_; }

  // The summary of a run that ended with `status` at x where f = F(x) (n or m entries): counts,
  // the monitor's figures, ‖F‖∞ (inf when f is not finite), the answer for usable() judged by
  // `given`, the criteria the user gave (minimised: a least-squares answer, ‖F‖ need not be 0).
  template <typename Residual>
  void finish(Summary& s, Status status, const StopMonitor& monitor, const Vector<N>& x,
              const Residual& f, const StopCriteria& given, bool minimised = false) const {
    s.status = status;
    s.function_evaluations = evaluations_;
    s.jacobian_evaluations = jacobians_;
    monitor.fill(s, f.allFinite() ? f.template lpNorm<Eigen::Infinity>()
                                  : std::numeric_limits<double>::infinity());
    s.record_answer(x, given, minimised);
  }

 private:
  int max_evaluations_ = 0, evaluations_ = 0, jacobians_ = 0;
  double usable_residual_ = 0.0;  // max(residual_tolerance, acceptance_tolerance)
  ProgressWindow progress_;
  Box<N> box_;
};

// F = G − x (or the problem's own F) and J_F of a square problem, evaluated and counted in a
// SolveLedger. The engines keep their loops in solve() itself, between start()/first_residual()
// and finish(): wrapped in a lambda that a shared run() calls, the loop cost Newton and Broyden
// 4–6 % more instructions at n = 2 (callgrind; the SSE stores of fixed-size Eigen code may alias
// the closure, so every captured local is reloaded after them).
template <int N>
class SquareSystem : public SolveLedger<N> {
 public:
  // A new solve of `problem` from x0 (checked: size, finite, inside `bounds`). Sizes the
  // workspace (at a fixed N nothing allocates). stop: as SolveLedger::start's.
  void start(std::string_view engine, const FixedPointProblem<N>& problem, const Vector<N>& x0,
             const BoxBounds& bounds, FiniteDifference scheme, const StopCriteria& stop) {
    check_initial_guess(engine, problem, x0);
    SolveLedger<N>::start(engine, bounds, x0, stop);
    problem_ = &problem;
    scheme_ = scheme;
    if constexpr (N == Dynamic) g_.resize(x0.size()), fd_.resize(x0.size());
  }

  // The run's first residual, f = F(x0): kNonFinite when it is not finite, kConverged when x0
  // already solves F (solved_at_start), nullopt when the engine is to iterate.
  std::optional<Status> first_residual(const Vector<N>& x0, Vector<N>& f,
                                       const StopCriteria& stop) {
    if (!residual(x0, f)) return Status::kNonFinite;
    if (solved_at_start(f, stop)) return Status::kConverged;
    return std::nullopt;
  }

  // f = F(x) = G(x) − x (the problem's own F when it has one); false when a value is not finite.
  bool residual(const Vector<N>& x, Vector<N>& f) {
    if (problem_->has_residual()) {
      problem_->residual(x, f);
      check_output_size(*problem_, f);
    } else {
      problem_->evaluate(x, g_);
      check_output_size(*problem_, g_);
      f = g_ - x;
    }
    const bool finite = f.allFinite();
    this->count_evaluation(finite ? f.stableNorm() : std::numeric_limits<double>::infinity());
    return finite;
  }

  // jac = J_F(x) where f = F(x): the problem's ∂G (user or AD) or differences, minus I. nullopt,
  // or the status to stop with: kMaxEvaluations when the differences would overrun the budget,
  // kNonFinite (message set) when J is not finite.
  std::optional<Status> jacobian(const Vector<N>& x, const Vector<N>& f, Matrix<N, N>& jac,
                                 std::string& message) {
    if (!problem_->has_jacobian() && !this->affords(finite_difference_cost(scheme_, x.size()))) {
      return Status::kMaxEvaluations;
    }
    int spent = 0;
    if (problem_->has_jacobian() && problem_->has_residual()) {
      problem_->residual_jacobian(x, jac);  // ∂F itself
    } else {
      if (problem_->has_jacobian()) {
        problem_->jacobian(x, jac);
      } else {
        g_ = f + x;
        spent = finite_difference_jacobian(*problem_, x, g_, jac, scheme_, fd_, &this->box());
      }
      jac.diagonal().array() -= 1.0;
    }
    this->count_jacobian(spent);
    if (!jac.allFinite()) {
      message = "the Jacobian of F is not finite";
      return Status::kNonFinite;
    }
    return std::nullopt;
  }

  // jac = J_F(x) from the problem's sparse residual Jacobian (run-time size; the caller checked
  // problem().sparse_residual_jacobian()), f = F(x). As jacobian(): nullopt or the status. A J of
  // another structure than the source's pattern (a user's evaluate) is refused: the engines
  // address its entries through the pattern.
  std::optional<Status> sparse_jacobian(const Vector<N>& x, const Vector<N>& f, SparseJacobian& jac,
                                        std::string& message) {
    SparseJacobianState& state = *problem_->sparse_jacobian_state();
    const SparseJacobianSource& sparse = *state.get();
    if (!this->affords(sparse.evaluations_per_jacobian)) return Status::kMaxEvaluations;
    this->count_jacobian(evaluate_sparse_jacobian(state, x, f, jac));
    if (detail::first_non_finite_row(jac) >= 0) {
      message = "the Jacobian of F is not finite";
      return Status::kNonFinite;
    }
    return std::nullopt;
  }

  const FixedPointProblem<N>& problem() const { return *problem_; }

 private:
  const FixedPointProblem<N>* problem_ = nullptr;
  FiniteDifference scheme_ = FiniteDifference::kCentral;
  Vector<N> g_ = zero_vector<N>();
  FiniteDifferenceWorkspace<N> fd_;
};

// The path of the engines on F for LineSearch (line_search.hpp): x(t) = P(x + t d), projected
// onto the system's box, the merit m = ‖F‖₂², the trial point in `xt` and F there in `ft`.
// δm(t) = 2∇φᵀ(x(t) − x) with ∇φ = J_Fᵀ F (`gradient`, φ = ½‖F‖₂²) when slope_from_gradient — a
// path the box may cut, an inexact (Krylov) step, the steepest-descent path — else −2t‖F‖₂²,
// exact for the Newton step d = −J_F⁻¹F and the model's prediction for a quasi-Newton one.
template <int N>
class ResidualPath {
 public:
  ResidualPath(SquareSystem<N>& system, const Vector<N>& x, double merit, const Vector<N>& d,
               const Vector<N>& gradient, bool slope_from_gradient, Vector<N>& xt, Vector<N>& ft)
      : system_(system),
        x_(x),
        d_(d),
        gradient_(gradient),
        xt_(xt),
        ft_(ft),
        merit_(merit),
        slope_from_gradient_(slope_from_gradient) {}

  bool exhausted() const { return system_.budget_spent(); }
  bool move(double t) {
    t_ = t;
    xt_ = x_ + t * d_;
    projected_ = system_.box().project(xt_, x_);
    return projected_ && xt_ == x_;
  }
  double slope() const {
    return slope_from_gradient_ ? 2.0 * gradient_.dot(xt_ - x_) : -2.0 * t_ * merit_;
  }
  double merit() {
    return system_.residual(xt_, ft_) ? ft_.squaredNorm()
                                      : std::numeric_limits<double>::quiet_NaN();
  }
  // The box cut the last move short.
  bool projected() const { return projected_; }

 private:
  SquareSystem<N>& system_;
  const Vector<N>&x_, &d_, &gradient_;
  Vector<N>&xt_, &ft_;
  double merit_, t_ = 0.0;
  bool slope_from_gradient_, projected_ = false;
};

}  // namespace nlobs::detail
