#pragma once
// Pseudo-transient continuation for F(x) = G(x) − x = 0 ([KK98]): follow a flow to its steady
// state by linearly implicit Euler steps whose pseudo time step δ grows as ‖F‖ falls (switched
// evolution relaxation):
//   ẋ = σ F(x):   (δ_k⁻¹ I − σ J(x_k)) p_k = σ F(x_k),   x_{k+1} = x_k + p_k,
//   δ_{k+1} = γ δ_k ‖F(x_{k−1})‖₂/‖F(x_k)‖₂, capped at max_pseudo_step,
// γ = pseudo_step_growth ≥ 1 (1: Kelley–Keyes' SER; PETSc's TSPseudo multiplies by 1.1, its
// -ts_pseudo_increment): with γ = 1, δ grows only as fast as ‖F‖ falls, which on a discretised
// elliptic problem scaled by h² its slowest mode (eigenvalue ~ 2π²h²) sets — thousands of steps.
// σ = −1 (Flow::kResidual, the default): ẋ = −F(x), Kelley–Keyes' u_t = −F(u) for a root
// problem F(x) = 0 adapted with Ψ = I (to_fixed_point); its roots attract where the eigenvalues
// of J have positive real parts (discretised elliptic problems, gradients of convex functions).
// σ = +1 (Flow::kFixedPoint): ẋ = G(x) − x, the flow whose explicit Euler step with δ = 1 is
// Picard's x ← G(x); its fixed points attract where every eigenvalue of ∂G has real part < 1 (a
// weaker condition than Picard's ρ(∂G) < 1). Small δ follows the flow (robust far from a root,
// where Newton's local model is useless); large δ is Newton (quadratic convergence near the root).
// A root the chosen flow leaves is not reached: the run ends without converging.
//
// Stop rules. Converged: StopCriteria's residual criterion, or its step criterion on a
// Newton-like step (‖p‖ ≤ 0.01 δ ‖F‖: the step solves J p = −F to a residual of 0.01 ‖F‖; a step
// that is small because δ is small is not Newton-like). A trial point where F is not finite
// halves δ and retries from the same iterate; δ below min_pseudo_step ends the run non_finite.
// A step lost to rounding (x + p == x while F ≠ 0) doubles δ and retries, without evaluating F.
// δ₀ and δ_min are at least ε (PseudoTransientOptions::kMinPseudoStep). ‖F‖ may rise along the way
// (the flow is followed, not ‖F‖ minimised): StopCriteria's stagnation rule is not applied;
// max_iterations, max_evaluations and divergence_limit are.
//
// Bounds (Engine::set_bounds): x_{k+1} = P(x_k + p_k), the projection onto the box (a step the
// box cut short is no step criterion); where the box holds x_k in place the flow leaves the box
// there, and the run ends blocked_by_bound.
//
// Sparse path (run-time size, a problem with a sparse Jacobian, declared or detected: as
// NewtonEngine's): δ⁻¹I ∓ J is assembled sparse on J's pattern and solved by
// PseudoTransientOptions::linear_solver (nlobs/solvers/linear/), a Krylov solver to
// linear_tolerance (the Newton-like step test assumes the step solves its system). A singular
// δ⁻¹I ∓ J halves δ as on the dense path, and so does a Krylov solve that breaks down or misses
// the tolerance (a smaller δ makes the matrix more diagonally dominant); the linear solver's other
// failures end the run, named.
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "nlobs/solvers/engine.hpp"
#include "nlobs/solvers/engine_spec.hpp"
#include "nlobs/solvers/finite_difference.hpp"
#include "nlobs/solvers/library_sizes.hpp"
#include "nlobs/solvers/sparse_path.hpp"
#include "nlobs/solvers/square_system.hpp"
#include "nlobs/solvers/stop_monitor.hpp"

namespace nlobs {

struct PseudoTransientOptions {
  enum class Flow { kResidual, kFixedPoint };  // ẋ = −(G(x) − x)  or  ẋ = G(x) − x
  // On the MGH root problems the residual flow solves 30 of 57 runs, the fixed-point flow 17.
  Flow flow = Flow::kResidual;
  // δ₀ ≥ kMinPseudoStep (ε ≈ 2.2e-16): below it x + δF == x in double precision wherever
  // |F| ≤ |x|, and the flow is not followed at all.
  double initial_pseudo_step = 1e-2;
  double max_pseudo_step = 1e12;  // δ_max ≥ δ₀, finite: beyond it the step is Newton's
  // γ in δ_{k+1} = γ δ_k ‖F_{k−1}‖/‖F_k‖: finite, in [1, 10].
  double pseudo_step_growth = 1.0;
  double min_pseudo_step =
      1e-12;  // δ_min ∈ [kMinPseudoStep, δ₀]: after NaN trials, give up below it
  static constexpr double kMinPseudoStep = std::numeric_limits<double>::epsilon();
  // Used only when the problem carries no Jacobian.
  FiniteDifference finite_difference = FiniteDifference::kCentral;
  // The sparse path's linear solver: as NewtonOptions::linear_solver ("auto", "dense", or a
  // make_linear_solver spec). Read only for problems with a sparse Jacobian.
  std::string linear_solver = "auto";
  // ‖b − A p‖₂ ≤ linear_tolerance ‖b‖₂ for a Krylov solver, in (0, 1) (direct ones solve exactly).
  double linear_tolerance = 1e-6;

  // Throws InvalidInput naming the field, its value and the requirement (options_validation.hpp).
  void validate() const;
  // The engine as the registry lists it, the spec keys (field names; older ones as aliases) and
  // their reading over these values (src/options/pseudo_transient_options.cpp).
  static EngineDescription describe();
  void read(EngineSpecReader& spec);
};

template <int N = Dynamic>
class PseudoTransientEngine : public Engine<N> {
 public:
  using Options = PseudoTransientOptions;

  explicit PseudoTransientEngine(PseudoTransientOptions ptc = {}, SolverOptions options = {})
      : Engine<N>(std::move(options)), ptc_(std::move(ptc)) {
    ptc_.validate();
    detail::require_lipschitz_for_error_bound(name(), this->options_.stop);
  }

  std::string_view name() const override { return "pseudo-transient"; }
  const PseudoTransientOptions& pseudo_transient_options() const { return ptc_; }
  bool accepts_bounds() const override { return true; }
  bool accepts_strict_bounds() const override { return true; }
  bool accepts_scaling() const override { return true; }
  bool has_sparse_path() const override {
    return detail::takes_sparse_path(ptc_.linear_solver, dense_reason());
  }

  Summary solve(const FixedPointProblem<N>& problem, Vector<N>& x) override;

 private:
  PseudoTransientOptions ptc_;
  Vector<N> x_ = zero_vector<N>(), f_ = zero_vector<N>(), p_ = zero_vector<N>(),
            xt_ = zero_vector<N>(), ft_ = zero_vector<N>();
  Matrix<N, N> jac_, shifted_;
  Eigen::PartialPivLU<Matrix<N, N>> lu_;
  // The sparse path (run-time size only): J, δ⁻¹I ∓ J, where each row's diagonal entry lies in
  // their value arrays, the linear solver.
  SparseJacobian sparse_jac_, sparse_shifted_;
  std::vector<Index> diagonal_;
  detail::SparseLinearStep linear_;
  // What sends a solve to the dense path whatever the problem carries: nothing (a scaling keeps
  // the sparse path: the scaled problem carries D_f J D_u⁻¹, scaling.hpp).
  const char* dense_reason() const { return nullptr; }
  // J_F at x_ into sparse_jac_ (sparse path); nullopt or the status.
  std::optional<Status> sparse_jacobian(std::string& message);
  // p_ = (δ⁻¹I − σJ)⁻¹ F (then negated for σ = −1) by LU of shifted_ or by linear_: nullopt, or
  // the status with `retry` set when a smaller δ may succeed (a singular matrix, a Krylov solve
  // that failed): δ is then halved and the step tried again.
  std::optional<Status> dense_shifted_solve(double delta, int sigma, bool& retry,
                                            std::string& message);
  std::optional<Status> sparse_shifted_solve(double delta, int sigma, bool& retry,
                                             std::string& message);
  // Doublings of δ per iteration for steps lost to rounding: from ε to 1e12 takes 93.
  static constexpr int kMaxLostSteps = 200;
  detail::SquareSystem<N> system_;
};

template <int N>
Summary PseudoTransientEngine<N>::solve(const FixedPointProblem<N>& problem, Vector<N>& x) {
  detail::refuse_dense_path_for_declared(
      name(), problem, ptc_.linear_solver, dense_reason(),
      "PseudoTransientOptions::linear_solver = \"dense\" for a small problem");
  if (std::optional<Summary> scaled = this->solve_scaled(*this, problem, x)) {
    return std::move(*scaled);
  }
  StopCriteria stop = this->options_.stop;
  stop.stagnation_patience = 0;  // ‖F‖ and the steps may grow along the flow
  system_.start(name(), problem, x, this->bounds_, ptc_.finite_difference, stop);
  const detail::Box<N>& box = system_.box();
  const Index n = x.size();
  bool sparse = false;
  if constexpr (N == Dynamic) {
    for (Vector<N>* v : {&x_, &f_, &p_, &xt_, &ft_}) v->resize(n);
    const SparseJacobianSource* source =
        detail::sparse_path_source(problem, x, ptc_.linear_solver, dense_reason());
    sparse = source != nullptr;
    if (sparse) {
      const SparsityPattern& pattern = *source->pattern;
      diagonal_.assign(static_cast<std::size_t>(n), -1);
      for (Index i = 0; i < n; ++i) {
        for (Index k = pattern.row_start[i]; k < pattern.row_start[i + 1]; ++k) {
          if (pattern.columns[k] == i) diagonal_[i] = k;
        }
        if (diagonal_[i] < 0) {
          throw InvalidInput(
              "pseudo-transient: the sparse Jacobian's pattern lacks the diagonal "
              "entry (" +
              std::to_string(i) + ", " + std::to_string(i) +
              "), where delta^-1 I is added (the problems of "
              "sparse_problem.hpp have every one)");
        }
      }
      linear_.choose(ptc_.linear_solver, pattern, n);
    } else {
      jac_.resize(n, n), shifted_.resize(n, n);
      if (lu_.rows() != n) lu_ = Eigen::PartialPivLU<Matrix<N, N>>(n);
    }
  }
  Summary summary;
  summary.engine = name();
  StopMonitor monitor(stop, x.template lpNorm<Eigen::Infinity>(), /*estimate_lipschitz=*/false);

  x_ = x;
  std::optional<Status> status = system_.first_residual(x_, f_, stop);
  double fnorm = f_.stableNorm();  // overflow-safe
  double delta = ptc_.initial_pseudo_step;
  const int sigma = ptc_.flow == PseudoTransientOptions::Flow::kFixedPoint ? 1 : -1;

  // Why budget_spent(). Out of progress where a bound holds a component against the flow σF and
  // that component's |F_i| is the largest: blocked there. The flow may still be settling the free
  // components, but ‖F‖ is then the held component's, which no longer falls (and switched
  // evolution relaxation, growing δ with ‖F‖⁻¹, keeps their steps small: ~700 to settle them in
  // tests/test_strict_bounds.cpp). A held component with a small F_i blocks nothing, nor does one
  // where ‖F‖∞ is small enough to use (a stagnated answer is usable there, a blocked one never).
  const double usable_residual =
      std::max(stop.residual_tolerance.value_or(0.0), stop.acceptance_tolerance);
  auto spent_status = [&] {
    Status spent = system_.spent_status(summary.message);
    if (spent != Status::kStagnated || !box.active()) return spent;
    std::optional<Index> largest_held;
    for (Index i = 0; i < n; ++i) {
      if (box.held(i, x_[i], sigma * f_[i], 0.0) &&
          (!largest_held || std::abs(f_[i]) > std::abs(f_[*largest_held]))) {
        largest_held = i;
      }
    }
    const double fmax = f_.template lpNorm<Eigen::Infinity>();
    if (!largest_held || std::abs(f_[*largest_held]) < fmax || fmax <= usable_residual) {
      return spent;
    }
    summary.message = box.blocked_message(*largest_held, x_, fmax, "the pseudo-transient flow");
    return Status::kBlockedByBound;
  };

  bool projected = false;
  while (!status) {
    if (system_.budget_spent()) {
      status = spent_status();
      break;
    }
    if (sparse) {
      status = sparse_jacobian(summary.message);
    } else {
      status = system_.jacobian(x_, f_, jac_, summary.message);  // J_F = ∂G − I
    }
    if (status) break;
    // Trial steps from x_k: a non-finite F(x_k + p) halves δ and tries again.
    bool stepped = false;
    int lost_steps = 0;
    while (!status && !stepped) {
      // σ = +1: (δ⁻¹I − J) p = F;  σ = −1: (δ⁻¹I + J) p = −F, p in p_.
      bool retry = false;
      std::string failure;  // the summary's message only if the run ends with it
      status = sparse ? sparse_shifted_solve(delta, sigma, retry, failure)
                      : dense_shifted_solve(delta, sigma, retry, failure);
      // δ⁻¹ at an eigenvalue of ±J makes the system singular though J is not: a smaller δ moves
      // away from it, as after a non-finite trial.
      if (retry && delta * 0.5 >= ptc_.min_pseudo_step) {
        status.reset();
        delta *= 0.5;
        continue;
      }
      if (status) {
        std::ostringstream os;
        os << (sigma > 0 ? "delta^-1 I - J" : "delta^-1 I + J") << " at iteration "
           << monitor.iterations() + 1 << " (delta " << delta << "): " << failure;
        summary.message = os.str();
        break;
      }
      if (sigma < 0) p_ = -p_;
      if (system_.budget_spent()) {
        status = spent_status();
        break;
      }
      xt_ = x_ + p_;
      projected = box.project(xt_, x_);
      if (projected && xt_ == x_) {
        if (const std::optional<Index> i = box.blocking(x_, p_, detail::BoxMove::kStep)) {
          summary.message = box.blocked_message(*i, x_, f_.template lpNorm<Eigen::Infinity>(),
                                                "the pseudo-transient flow");
          status = Status::kBlockedByBound;
          break;
        }
      }
      // A step lost to rounding (x + p == x although F ≠ 0: δ|F| below the spacing of x) is no
      // step at all, least of all a converged one: δ doubles, without an evaluation of F, up to
      // δ_max (where p is Newton's step and its smallness is convergence).
      if (!projected && xt_ == x_ && delta < ptc_.max_pseudo_step && lost_steps < kMaxLostSteps) {
        ++lost_steps;
        delta = std::min(2.0 * delta, ptc_.max_pseudo_step);
        continue;
      }
      if (p_.allFinite() && system_.residual(xt_, ft_)) {
        stepped = true;
      } else {
        delta *= 0.5;
        if (delta < ptc_.min_pseudo_step) {
          std::ostringstream os;
          os << "F is not finite along the pseudo-transient path: delta fell below "
             << ptc_.min_pseudo_step;
          summary.message = os.str();
          status = Status::kNonFinite;
        }
      }
    }
    if (status) break;
    const double previous = fnorm;
    if (projected) p_ = xt_ - x_;  // the step taken
    x_ = xt_;
    std::swap(f_, ft_);
    fnorm = f_.stableNorm();
    const double step = p_.template lpNorm<Eigen::Infinity>();
    // Newton-like: the pseudo-time term δ⁻¹p = σ(F + Jp) is below 1 % of ‖F‖, so the step
    // solves the Newton equation to a residual of 0.01 ‖F‖.
    // stableNorm: at a tiny δ, ‖p‖₂² underflows and norm() says 0, which once passed a step of
    // 1e-299 at δ = 1e-300 as Newton-like (and converged).
    const bool newton_like = !projected && p_.stableNorm() <= 0.01 * delta * previous;
    status = monitor.update(step, f_.template lpNorm<Eigen::Infinity>(),
                            x_.template lpNorm<Eigen::Infinity>(), newton_like);
    this->after_iteration(summary, status, monitor.iterations(), step,
                          f_.template lpNorm<Eigen::Infinity>(), x_);
    if (!status && fnorm == 0.0) status = Status::kConverged;
    // Switched evolution relaxation.
    if (fnorm > 0.0) {
      delta = std::clamp(ptc_.pseudo_step_growth * delta * previous / fnorm, ptc_.min_pseudo_step,
                         ptc_.max_pseudo_step);
    }
  }

  x = x_;
  system_.finish(summary, *status, monitor, x, f_, this->options_.stop);
  if (sparse) linear_.report(summary);
  return summary;
}

template <int N>
std::optional<Status> PseudoTransientEngine<N>::dense_shifted_solve(double delta, int sigma,
                                                                    bool& retry,
                                                                    std::string& message) {
  if (sigma > 0) {
    shifted_ = -jac_;
  } else {
    shifted_ = jac_;
  }
  shifted_.diagonal().array() += 1.0 / delta;
  lu_.compute(shifted_);
  const double smallest_pivot = lu_.matrixLU().diagonal().cwiseAbs().minCoeff();
  if (!(smallest_pivot > 1e-13 * shifted_.cwiseAbs().maxCoeff())) {
    std::ostringstream os;
    os << "singular (smallest LU pivot " << smallest_pivot << ")";
    message = os.str();
    retry = true;
    return Status::kSingularJacobian;
  }
  p_ = lu_.solve(f_);
  return std::nullopt;
}

template <int N>
std::optional<Status> PseudoTransientEngine<N>::sparse_jacobian(std::string& message) {
  if constexpr (N == Dynamic) {
    return system_.sparse_jacobian(x_, f_, sparse_jac_, message);
  } else {
    static_cast<void>(message);
    return Status::kInvalidInput;  // unreachable: fixed sizes have no sparse path
  }
}

template <int N>
std::optional<Status> PseudoTransientEngine<N>::sparse_shifted_solve(double delta, int sigma,
                                                                     bool& retry,
                                                                     std::string& message) {
  if constexpr (N == Dynamic) {
    sparse_shifted_ = sparse_jac_;
    double* values = sparse_shifted_.valuePtr();
    if (sigma > 0) {
      for (Index k = 0; k < sparse_shifted_.nonZeros(); ++k) values[k] = -values[k];
    }
    for (const Index k : diagonal_) values[k] += 1.0 / delta;
    const LinearStatus linear =
        linear_.solve(sparse_shifted_, f_, p_, ptc_.linear_tolerance, ptc_.linear_tolerance);
    retry = linear == LinearStatus::kSingular ||
            (linear_.iterative() &&
             (linear == LinearStatus::kNotConverged || linear == LinearStatus::kBreakdown));
    return linear_.failure(linear, message);
  } else {
    static_cast<void>(delta), static_cast<void>(sigma), static_cast<void>(retry);
    static_cast<void>(message);
    return Status::kInvalidInput;  // unreachable: fixed sizes have no sparse path
  }
}

// Compiled once in the library for its sizes (nlobs/solvers/library_sizes.hpp).
#define NLOBS_EXTERN_PSEUDO_TRANSIENT_ENGINE(n) extern template class PseudoTransientEngine<n>;
NLOBS_FOR_EACH_LIBRARY_SIZE(NLOBS_EXTERN_PSEUDO_TRANSIENT_ENGINE)
#undef NLOBS_EXTERN_PSEUDO_TRANSIENT_ENGINE

}  // namespace nlobs
