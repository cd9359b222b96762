#pragma once
// A fixed-point engine = the Picard loop x ← G(x) + a pluggable accelerator.
//
// The accelerator sees each evaluated pair (x, G(x)) — the iterate history — and proposes the
// next point at which to evaluate G. It also says whether that evaluation completed an
// iteration of the engine's own sequence (the points the stop criteria watch and the engine
// returns): Steffensen needs two evaluations per iteration, Aitken's accelerated sequence
// runs beside the Picard sequence it transforms. Picard is the engine with no accelerator.
//
// An accelerator is any type with
//   std::string_view name() const;
//   void start(const Vector<N>& x0);     // new solve; size the workspace here (dynamic N)
//   bool propose(const Vector<N>& x, const Vector<N>& gx, Vector<N>& next, Vector<N>& estimate);
// propose() writes the next evaluation point to `next`; when it returns true, `estimate` holds
// the new iterate of the engine's sequence. A user's accelerator plugs in as
// AcceleratedEngine<N, MyAccelerator<N>> without touching the library (docs/extending.md).
#include <cmath>
#include <concepts>
#include <limits>
#include <optional>
#include <string_view>
#include <utility>

#include "nlobs/solvers/engine.hpp"
#include "nlobs/solvers/stop_monitor.hpp"

namespace nlobs {

template <typename A, int N>
concept FixedPointAccelerator = requires(A a, const A ca, const Vector<N>& x, Vector<N>& out) {
  { ca.name() } -> std::convertible_to<std::string_view>;
  {a.start(x)};
  { a.propose(x, x, out, out) } -> std::same_as<bool>;
};

// An accelerator whose estimates are plain Picard steps declares
//   static constexpr bool kPicardSteps = true;
// which lets the engine estimate G's Lipschitz constant from the step ratios.
template <typename A>
constexpr bool has_picard_steps() {
  if constexpr (requires { A::kPicardSteps; }) {
    return A::kPicardSteps;
  } else {
    return false;
  }
}

// An accelerator whose iterates' steps and residuals rise and fall by design (Anderson) declares
//   static constexpr bool kNonMonotone = true;
// and the engine judges stagnation and divergence by the best residual over
// StopCriteria::residual_window iterations instead of by the last steps.
template <typename A>
constexpr bool is_non_monotone() {
  if constexpr (requires { A::kNonMonotone; }) {
    return A::kNonMonotone;
  } else {
    return false;
  }
}

template <int N, FixedPointAccelerator<N> Accelerator>
class AcceleratedEngine : public Engine<N> {
 public:
  explicit AcceleratedEngine(SolverOptions options = {}, Accelerator accelerator = {})
      : Engine<N>(std::move(options)), accelerator_(std::move(accelerator)) {
    if (!has_picard_steps<Accelerator>()) {
      detail::require_lipschitz_for_error_bound(name(), this->options_.stop);
    }
  }

  std::string_view name() const override { return accelerator_.name(); }
  bool needs_contraction() const override { return true; }
  Accelerator& accelerator() { return accelerator_; }

  Summary solve(const FixedPointProblem<N>& problem, Vector<N>& x) override;

 private:
  Accelerator accelerator_;
  Vector<N> point_ = zero_vector<N>(), gx_ = zero_vector<N>(), next_ = zero_vector<N>(),
            estimate_ = zero_vector<N>(), last_ = zero_vector<N>();
};

template <int N, FixedPointAccelerator<N> Accelerator>
Summary AcceleratedEngine<N, Accelerator>::solve(const FixedPointProblem<N>& problem,
                                                 Vector<N>& x) {
  detail::check_initial_guess(name(), problem, x);
  const SolverOptions& opt = this->options_;
  Summary summary;
  summary.engine = name();

  if constexpr (N == Dynamic) {  // allocates only when n changes
    const Index n = x.size();
    point_.resize(n), gx_.resize(n), next_.resize(n), estimate_.resize(n), last_.resize(n);
  }
  StopMonitor monitor(opt.stop, x.template lpNorm<Eigen::Infinity>(),
                      has_picard_steps<Accelerator>(),
                      is_non_monotone<Accelerator>() ? StopMonitor::Progress::kBestResidual
                                                     : StopMonitor::Progress::kSteps,
                      x.size());
  accelerator_.start(x);
  point_ = x;
  last_ = x;
  int evaluations = 0;
  std::optional<Status> status;
  while (!status) {
    if (evaluations >= opt.stop.max_evaluations) {
      status = Status::kMaxEvaluations;
      break;
    }
    problem.evaluate(point_, gx_);
    ++evaluations;
    detail::check_output_size(problem, gx_);
    if (!gx_.allFinite()) {
      status = Status::kNonFinite;
      break;
    }
    if constexpr (has_picard_steps<Accelerator>()) {
      // Plain Picard: the step is the residual at the previous point; no copies needed.
      const double step = (gx_ - point_).template lpNorm<Eigen::Infinity>();
      point_.swap(gx_);
      status = monitor.update(step, step, point_.template lpNorm<Eigen::Infinity>());
      this->after_iteration(summary, status, monitor.iterations(), step, step, point_);
      continue;
    } else {
      const double residual = (gx_ - point_).template lpNorm<Eigen::Infinity>();
      const bool completed = accelerator_.propose(point_, gx_, next_, estimate_);
      if (completed) {
        if (!estimate_.allFinite()) {
          status = Status::kNonFinite;
          break;
        }
        const double step = (estimate_ - last_).template lpNorm<Eigen::Infinity>();
        last_ = estimate_;
        status = monitor.update(step, residual, last_.template lpNorm<Eigen::Infinity>());
        this->after_iteration(summary, status, monitor.iterations(), step, residual, last_);
      }
      point_.swap(next_);
    }
  }
  if constexpr (has_picard_steps<Accelerator>()) last_ = point_;

  // Report the residual at the point returned: one more evaluation, counted.
  x = last_;
  problem.evaluate(x, gx_);
  ++evaluations;
  detail::check_output_size(problem, gx_);
  const double residual = gx_.allFinite() ? (gx_ - x).template lpNorm<Eigen::Infinity>()
                                          : std::numeric_limits<double>::infinity();
  summary.status = *status;
  summary.function_evaluations = evaluations;
  monitor.fill(summary, residual);
  summary.record_answer(x, opt.stop);
  return summary;
}

}  // namespace nlobs
