#pragma once
// Powell's hybrid method for F(x) = G(x) − x = 0 ([Pow70]; MINPACK's hybrj, [MINPACK80] §4): a
// trust region ‖D p‖₂ ≤ Δ around x, a dogleg step inside it between the Gauss–Newton step
// p_N = −J⁻¹F and the scaled steepest-descent (Cauchy) step, and Broyden rank-one updates of the
// QR factors of J between Jacobian evaluations:
//   J⁺ = J + (F(x+p) − F(x) − J p) (D²p)ᵀ / ‖D p‖²,   kept as Q⁺R⁺ by Givens rotations, O(n²).
// The Jacobian is evaluated again only after two consecutive failed steps (ratio < 0.1), as
// MINPACK does; a step is accepted when the actual reduction of ‖F‖₂ is at least 1e-4 of the
// reduction the linear model predicts. ‖F‖₂ never increases from one accepted iterate to the
// next.
//
// Stop rules. Converged: StopCriteria's residual criterion, or its step criterion for a step
// that was the full Gauss–Newton step (a step the radius cut short says nothing about the
// distance to a root). Stagnated, with the reason in Summary::message: MINPACK's tests — the
// radius below ε‖D x‖₂ (no further improvement possible), no reduction of at least 10 % over
// the last five Jacobians, or of at least 0.1 % over the last ten iterations. StopCriteria's
// stagnation_patience (a rule for monotone fixed-point steps; the radius makes steps grow and
// shrink by design) is not used. A non-finite F at a trial point is a failed step: the radius
// shrinks and the last good iterate is kept.
//
// Bounds (Engine::set_bounds): the trial point is P(x + p), the projection onto the box, and the
// step taken p' = P(x + p) − x is the one the ratio, the model ‖F + J p'‖ and the Broyden update
// use (a projected Gauss–Newton step is no step criterion). A stop of the progress tests at a
// point where a bound holds x against −∇(½‖F‖²) is blocked_by_bound.
#include <Eigen/Householder>
#include <Eigen/Jacobi>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string_view>
#include <utility>

#include "nlobs/solvers/engine.hpp"
#include "nlobs/solvers/engine_spec.hpp"
#include "nlobs/solvers/finite_difference.hpp"
#include "nlobs/solvers/library_sizes.hpp"
#include "nlobs/solvers/square_system.hpp"
#include "nlobs/solvers/stop_monitor.hpp"

namespace nlobs {

struct DoglegOptions {
  // The scaling D of the trust region ‖D p‖₂ ≤ Δ ([MINPACK80]'s `mode`):
  //   kNone: D = I (mode 2 with diag = 1, what MINPACK's hybrj1 driver uses);
  //   kJacobianColumns: D_jj = ‖J e_j‖₂ at the first Jacobian, then the running maximum over
  //   later Jacobians (mode 1; a zero column gives 1). Invariant to the scaling of x.
  enum class Scaling { kNone, kJacobianColumns };
  Scaling scaling = Scaling::kNone;
  // Initial radius Δ₀ = factor · ‖D x₀‖₂, or factor when x₀ = 0; MINPACK's `factor`, whose
  // recommended value is 100. Must be > 0.
  double initial_radius_factor = 100.0;
  // Broyden updates between Jacobians (false: a fresh Jacobian at every iterate, a trust-region
  // Newton with a dogleg step).
  bool broyden_updates = true;
  // Used only when the problem carries no Jacobian.
  FiniteDifference finite_difference = FiniteDifference::kCentral;

  // Throws InvalidInput naming the field, its value and the requirement (options_validation.hpp).
  void validate() const;
  // The engine as the registry lists it, the spec keys (field names; older ones as aliases) and
  // their reading over these values (src/options/dogleg_options.cpp).
  static EngineDescription describe();
  void read(EngineSpecReader& spec);
};

template <int N = Dynamic>
class DoglegEngine : public Engine<N> {
 public:
  using Options = DoglegOptions;

  explicit DoglegEngine(DoglegOptions dogleg = {}, SolverOptions options = {})
      : Engine<N>(std::move(options)), dogleg_(dogleg) {
    dogleg_.validate();
    detail::require_lipschitz_for_error_bound(name(), this->options_.stop);
  }

  std::string_view name() const override { return "dogleg"; }
  const DoglegOptions& dogleg_options() const { return dogleg_; }
  bool accepts_bounds() const override { return true; }
  bool accepts_strict_bounds() const override { return true; }
  bool accepts_scaling() const override { return true; }

  Summary solve(const FixedPointProblem<N>& problem, Vector<N>& x) override;

 private:
  // MINPACK's dogleg: the step p with ‖D p‖₂ ≤ Δ on the dogleg path, from R, Qᵀ F and D.
  void dogleg_step(double delta);
  // J ← J + Q u vᵀ with J = Q R: Givens rotations restore R to upper triangular form and carry
  // Q and qtf along ([GVL13] §6.5.1).
  void rank_one_update();

  DoglegOptions dogleg_;
  Vector<N> x_ = zero_vector<N>(), f_ = zero_vector<N>(), xt_ = zero_vector<N>(),
            ft_ = zero_vector<N>(), p_ = zero_vector<N>(), qtf_ = zero_vector<N>(),
            diag_ = zero_vector<N>(), u_ = zero_vector<N>(), v_ = zero_vector<N>(),
            gauss_newton_ = zero_vector<N>(), gradient_ = zero_vector<N>(),
            work_ = zero_vector<N>();
  Matrix<N, N> jac_, q_, r_;
  Eigen::HouseholderQR<Matrix<N, N>> qr_;
  Vector<N> householder_work_ = zero_vector<N>();
  detail::SquareSystem<N> system_;
  bool step_was_gauss_newton_ = false;
};

template <int N>
void DoglegEngine<N>::dogleg_step(double delta) {
  const Index n = r_.rows();
  const double eps = std::numeric_limits<double>::epsilon();
  // Gauss–Newton direction: R x = Qᵀ F by back substitution; a zero diagonal is replaced by
  // ε · (largest entry of its column), as MINPACK does, so a singular R still gives a direction.
  for (Index j = n - 1; j >= 0; --j) {
    double sum = qtf_[j];
    for (Index i = j + 1; i < n; ++i) sum -= r_(j, i) * gauss_newton_[i];
    double pivot = r_(j, j);
    if (pivot == 0.0) {
      const double largest = r_.col(j).head(j + 1).cwiseAbs().maxCoeff();
      pivot = largest > 0.0 ? eps * largest : eps;
    }
    gauss_newton_[j] = sum / pivot;
  }
  const double qnorm = diag_.cwiseProduct(gauss_newton_).norm();
  step_was_gauss_newton_ = qnorm <= delta;
  if (step_was_gauss_newton_) {
    p_ = -gauss_newton_;
    return;
  }
  // Scaled gradient direction D⁻¹ Rᵀ Qᵀ F and the minimiser of the model along it.
  gradient_.noalias() = r_.template triangularView<Eigen::Upper>().transpose() * qtf_;
  gradient_.array() /= diag_.array();
  const double gnorm = gradient_.norm();
  double sgnorm = 0.0;
  double alpha = delta / qnorm;
  if (gnorm != 0.0) {
    gradient_ = (gradient_ / gnorm).cwiseQuotient(diag_);
    work_.noalias() = r_.template triangularView<Eigen::Upper>() * gradient_;
    const double temp = work_.norm();
    sgnorm = (gnorm / temp) / temp;
    alpha = 0.0;
    if (sgnorm < delta) {
      // The Cauchy point lies inside the region: the dogleg point between it and p_N on the
      // boundary, written as MINPACK writes it to avoid cancellation.
      const double bnorm = qtf_.norm();
      double t = (bnorm / gnorm) * (bnorm / qnorm) * (sgnorm / delta);
      const double dq = delta / qnorm, sd = sgnorm / delta;
      t = t - dq * sd * sd + std::sqrt((t - dq) * (t - dq) + (1.0 - dq * dq) * (1.0 - sd * sd));
      alpha = dq * (1.0 - sd * sd) / t;
    }
  }
  const double along_gradient = (1.0 - alpha) * std::min(sgnorm, delta);
  p_ = -(along_gradient * gradient_ + alpha * gauss_newton_);
}

template <int N>
void DoglegEngine<N>::rank_one_update() {
  const Index n = r_.rows();
  Eigen::JacobiRotation<double> rotation;
  // Rotate u onto e₁ from the bottom up; R becomes upper Hessenberg.
  for (Index k = n - 1; k > 0; --k) {
    rotation.makeGivens(u_[k - 1], u_[k]);
    r_.applyOnTheLeft(k - 1, k, rotation.adjoint());
    q_.applyOnTheRight(k - 1, k, rotation);
    qtf_.applyOnTheLeft(k - 1, k, rotation.adjoint());
    u_.applyOnTheLeft(k - 1, k, rotation.adjoint());
  }
  r_.row(0) += u_[0] * v_.transpose();
  // Restore upper triangular form from the top down.
  for (Index k = 0; k + 1 < n; ++k) {
    rotation.makeGivens(r_(k, k), r_(k + 1, k));
    r_.applyOnTheLeft(k, k + 1, rotation.adjoint());
    q_.applyOnTheRight(k, k + 1, rotation);
    qtf_.applyOnTheLeft(k, k + 1, rotation.adjoint());
    r_(k + 1, k) = 0.0;
  }
}

template <int N>
Summary DoglegEngine<N>::solve(const FixedPointProblem<N>& problem, Vector<N>& x) {
  if (std::optional<Summary> scaled = this->solve_scaled(*this, problem, x)) {
    return std::move(*scaled);
  }
  StopCriteria stop = this->options_.stop;
  stop.stagnation_patience = 0;  // replaced by the trust region's own progress tests
  system_.start(name(), problem, x, this->bounds_, dogleg_.finite_difference, stop);
  const detail::Box<N>& box = system_.box();
  const Index n = x.size();
  if constexpr (N == Dynamic) {
    for (Vector<N>* v : {&x_, &f_, &xt_, &ft_, &p_, &qtf_, &diag_, &u_, &v_, &gauss_newton_,
                         &gradient_, &work_, &householder_work_}) {
      v->resize(n);
    }
    jac_.resize(n, n), q_.resize(n, n), r_.resize(n, n);
    if (qr_.rows() != n) qr_ = Eigen::HouseholderQR<Matrix<N, N>>(n, n);
  }
  Summary summary;
  summary.engine = name();
  StopMonitor monitor(stop, x.template lpNorm<Eigen::Infinity>(), /*estimate_lipschitz=*/false);
  const double eps = std::numeric_limits<double>::epsilon();

  x_ = x;
  std::optional<Status> status = system_.first_residual(x_, f_, stop);
  double fnorm = f_.stableNorm();  // overflow-safe, as MINPACK's enorm
  double delta = 0.0, xnorm = 0.0, last_step = 0.0;
  int slow_iterations = 0, slow_jacobians = 0;  // MINPACK's nslow1, nslow2
  bool accepted_any = false;  // until the first accepted step Δ ≤ ‖Dp‖ (MINPACK's iter = 1)
  int failures = 0, successes = 0;  // consecutive; MINPACK's ncfail, ncsuc

  // No further progress: blocked where the box holds x against −∇(½‖F‖²) = −Rᵀ Qᵀ F, else
  // stagnated for `why`.
  auto descent = [&]() -> const Vector<N>& {
    gradient_.noalias() = r_.template triangularView<Eigen::Upper>().transpose() * qtf_;
    gradient_ = -gradient_;
    return gradient_;
  };
  auto stop_stuck = [&](const char* why) {
    if (const std::optional<Index> i = box.blocking(x_, descent(), detail::BoxMove::kDirection)) {
      summary.message = box.blocked_message(*i, x_, f_.template lpNorm<Eigen::Infinity>(),
                                            "the descent direction");
      status = Status::kBlockedByBound;
    } else {
      summary.message = why;
      status = Status::kStagnated;
    }
  };
  // The budget or the progress window is spent: why (blocked where a bound holds x).
  auto spent_status = [&] {
    const bool factored = system_.jacobians() > 0;  // (the window needs one to expire)
    return system_.spent_status(summary.message, x_,
                                box.active() && factored ? descent() : gradient_,
                                f_.template lpNorm<Eigen::Infinity>());
  };
  int jacobians = 0;
  while (!status) {
    if (system_.budget_spent()) {
      status = spent_status();
      break;
    }
    // J_F = ∂G − I, factored J = Q R.
    if ((status = system_.jacobian(x_, f_, jac_, summary.message))) break;
    if (++jacobians == 1) {
      if (dogleg_.scaling == DoglegOptions::Scaling::kJacobianColumns) {
        diag_ = jac_.colwise().norm().transpose();
        for (Index j = 0; j < n; ++j) diag_[j] = diag_[j] == 0.0 ? 1.0 : diag_[j];
      } else {
        diag_.setOnes();
      }
      xnorm = diag_.cwiseProduct(x_).norm();
      delta = xnorm > 0.0 ? dogleg_.initial_radius_factor * xnorm : dogleg_.initial_radius_factor;
    } else if (dogleg_.scaling == DoglegOptions::Scaling::kJacobianColumns) {
      diag_ = diag_.cwiseMax(jac_.colwise().norm().transpose());
    }
    qr_.compute(jac_);
    r_ = qr_.matrixQR().template triangularView<Eigen::Upper>();
    qr_.householderQ().evalTo(q_, householder_work_);
    qtf_.noalias() = q_.transpose() * f_;

    bool fresh_jacobian = true;
    while (!status) {
      dogleg_step(delta);
      if (!accepted_any) delta = std::min(delta, diag_.cwiseProduct(p_).norm());
      if (system_.budget_spent()) {
        status = spent_status();
        break;
      }
      // In a box the step is P(x + p) − x: the model, the ratio and the update all use it. The
      // radius grows from the model's own step: a step the box cut short says nothing against
      // the model (on a strict bound each cut is 99 % of the room left, and Δ = 2‖Dp'‖ would
      // fall with it, 100-fold per step, leaving the free components behind).
      const double model_pnorm = diag_.cwiseProduct(p_).norm();
      xt_ = x_ + p_;
      const bool projected = box.project(xt_, x_);
      if (projected) {
        p_ = xt_ - x_;
        step_was_gauss_newton_ = false;
      }
      const double pnorm = diag_.cwiseProduct(p_).norm();
      if (projected && pnorm == 0.0) {
        // The box holds x against this step: no evaluation, no failure counted against the
        // Jacobian; a smaller radius turns the step towards −∇(½‖F‖²).
        delta *= 0.5;
        if (0.01 * delta > eps * xnorm) continue;
        stop_stuck("the trust radius fell below machine precision relative to |x|");
        break;
      }
      const bool finite = system_.residual(xt_, ft_);
      const double fnorm_trial =
          finite ? ft_.stableNorm() : std::numeric_limits<double>::infinity();
      // Actual and predicted reductions of ‖F‖₂², relative: 1 − (‖F⁺‖/‖F‖)², 1 − (‖F + Jp‖/‖F‖)².
      const double actual = fnorm_trial < fnorm ? 1.0 - std::pow(fnorm_trial / fnorm, 2) : -1.0;
      work_.noalias() = r_.template triangularView<Eigen::Upper>() * p_;
      work_ += qtf_;  // Qᵀ(F + J p)
      const double model_norm = work_.norm();
      const double predicted = model_norm < fnorm ? 1.0 - std::pow(model_norm / fnorm, 2) : 0.0;
      const double ratio = predicted > 0.0 ? actual / predicted : 0.0;

      if (ratio < 0.1) {
        successes = 0;
        ++failures;
        delta *= 0.5;
      } else {
        failures = 0;
        ++successes;
        if (ratio >= 0.5 || successes > 1) delta = std::max(delta, model_pnorm / 0.5);
        if (std::abs(ratio - 1.0) <= 0.1) delta = model_pnorm / 0.5;
      }
      const bool accepted = ratio >= 1e-4;
      std::optional<Status> monitor_status;
      if (accepted) {
        accepted_any = true;
        x_ = xt_;
        std::swap(f_, ft_);  // ft_ now holds F at the previous iterate
        fnorm = fnorm_trial;
        xnorm = diag_.cwiseProduct(x_).norm();
        last_step = p_.template lpNorm<Eigen::Infinity>();
        monitor_status =
            monitor.update(last_step, f_.template lpNorm<Eigen::Infinity>(),
                           x_.template lpNorm<Eigen::Infinity>(), step_was_gauss_newton_);
        this->after_iteration(summary, monitor_status, monitor.iterations(), last_step,
                              f_.template lpNorm<Eigen::Infinity>(), x_);
      }
      slow_iterations = actual >= 1e-3 ? 0 : slow_iterations + 1;
      if (fresh_jacobian) ++slow_jacobians;
      if (actual >= 0.1) slow_jacobians = 0;
      fresh_jacobian = false;  // the next trial uses an updated (or the same) Jacobian

      if (monitor_status) {
        status = monitor_status;
        break;
      }
      if (fnorm == 0.0) {
        status = Status::kConverged;
        break;
      }
      const char* why = nullptr;
      if (0.1 * std::max(0.1 * delta, pnorm) <= eps * xnorm) {
        why =
            "the trust radius fell below machine precision relative to |x|: no further "
            "improvement possible";
      } else if (dogleg_.broyden_updates && slow_jacobians == 5) {
        // (Without Broyden updates every iterate has a Jacobian: the ten-iteration rule below
        // is the one that measures progress.)
        why = "no 10% reduction of |F|2 over the last five Jacobian evaluations";
      } else if (slow_iterations == 10) {
        why = "no 0.1% reduction of |F|2 over the last ten iterations";
      }
      if (why) {
        stop_stuck(why);
        break;
      }
      // A fresh Jacobian after two failures (MINPACK); without Broyden updates after every
      // accepted step (after a rejected one the factors still hold J at x).
      if (dogleg_.broyden_updates ? failures == 2 : accepted) break;
      if (!dogleg_.broyden_updates) continue;

      // Broyden: u = Qᵀ(F⁺ − F − J p)/‖Dp‖ in Q's coordinates, v = D²p/‖Dp‖. On an accepted
      // step F⁺ is now f_; on a rejected one ft_.
      const Vector<N>& f_trial = accepted ? f_ : ft_;
      if (!f_trial.allFinite()) continue;  // nothing to learn from a non-finite value
      u_.noalias() = q_.transpose() * f_trial;
      if (accepted) {
        work_ = u_ - work_;  // Qᵀ F⁺ − Qᵀ(F + J p)
        qtf_ = u_;
        u_ = work_ / pnorm;
      } else {
        u_ = (u_ - work_) / pnorm;
      }
      v_ = diag_.cwiseProduct(diag_.cwiseProduct(p_) / pnorm);
      rank_one_update();
    }
  }

  x = x_;
  system_.finish(summary, *status, monitor, x, f_, this->options_.stop);
  return summary;
}

// Compiled once in the library for its sizes (nlobs/solvers/library_sizes.hpp).
#define NLOBS_EXTERN_DOGLEG_ENGINE(n) extern template class DoglegEngine<n>;
NLOBS_FOR_EACH_LIBRARY_SIZE(NLOBS_EXTERN_DOGLEG_ENGINE)
#undef NLOBS_EXTERN_DOGLEG_ENGINE

}  // namespace nlobs
