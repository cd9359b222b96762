#pragma once
// Levenberg–Marquardt for F(x) = 0, square (F = G − x) or least squares (F: Rⁿ → Rᵐ, m ≥ n), as
// Moré implements it ([Mor78]; MINPACK's lmder, [MINPACK80]): the step solves
//   min ‖F + J p‖₂² + λ ‖D p‖₂²,
// with λ ≥ 0 found by Moré's safeguarded Newton iteration on the secular equation ‖D p(λ)‖₂ = Δ
// (λ = 0 when the Gauss–Newton step fits in the trust region), on the QR factors of J with
// column pivoting, so the normal equations are never formed. D is I or Moré's scaling: the
// column norms of J, kept as a running maximum (invariant to a scaling of x).
// Optional geodesic acceleration ([TS12]): the velocity v = p(λ) is corrected by the
// acceleration a = argmin ‖J a + r_vv‖² + λ‖D a‖², r_vv ≈ (2/h)((F(x + h v) − F(x))/h − J v), and
// the step p = v + a/2 is taken only when 2‖D a‖ ≤ α ‖D v‖ (one more evaluation per step).
//
// Stop rules. Converged: StopCriteria's residual criterion, its step criterion on a step with
// λ = 0 (a Gauss–Newton step inside the region), or — least squares only, where ‖F‖ need not
// reach 0 — MINPACK's ftol (actual and predicted relative reductions of ‖F‖₂² both below it)
// and gtol (the cosine between F and every column of J below it). On a square system those two
// mean a local minimum of ‖F‖ that is not a root: stagnated, with the reason. Stagnated also:
// the radius below ε‖D x‖₂. A non-finite F at a trial point is a failed step.
//
// Bounds (Engine::set_bounds): the trial point is P(x + p), the projection onto the box; the
// ratio uses the reduction ‖F‖² − ‖F + J p'‖² the linear model predicts for the step taken,
// p' = P(x + p) − x (Moré's formula when nothing was projected). At each Jacobian the variables a
// bound holds against −Jᵀ F are frozen (an active set: their columns of J are zeroed, so the step
// leaves them and the badly scaled held ones do not swamp the free ones, as in scipy's dogbox).
// The gradient test then judges the free variables: a least-squares run has converged there (a
// minimum on the box) and a square one is blocked_by_bound, as is a stagnation where a bound
// holds x.
// Geodesic acceleration is refused with bounds (its second-difference point may leave the box).
//
// The step's linear algebra is a model: LmQrModel (dense J, QR with column pivoting, as MINPACK)
// or, at run-time size on a problem with a sparse Jacobian (declared, or detected by
// RootProblem::with_autodiff), LmNormalEquationsModel (the damped normal equations by CHOLMOD's
// sparse Cholesky; the same λ iteration, one factorisation per λ tried). Both give the loop below
// the same calls: jacobian() to fill, gradient, freeze, column_norms, factor (returning gtol's
// cosine), find_lambda (the step p(λ) in x's order), multiply (J p), damped_solve (the
// acceleration), report.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>

#include "nlobs/solvers/engine.hpp"
#include "nlobs/solvers/engine_spec.hpp"
#include "nlobs/solvers/finite_difference.hpp"
#include "nlobs/solvers/library_sizes.hpp"
#include "nlobs/solvers/square_system.hpp"
#include "nlobs/solvers/stop_monitor.hpp"
#include "nlobs/solvers/trust_region/lm_normal_equations_model.hpp"
#include "nlobs/solvers/trust_region/lm_qr_model.hpp"

namespace nlobs {

struct LevenbergMarquardtOptions {
  // D: Moré's scaling (column norms of J, running maximum; MINPACK's mode 1, what lmder1
  // uses), or D = I (the default: on the MGH systems it solves 49 of 57 runs, Moré's scaling
  // 42; docs/solvers.md).
  bool scale_by_jacobian_columns = false;
  // Δ₀ = factor · ‖D x₀‖₂ (factor when x₀ = 0); MINPACK's recommended 100. Must be > 0.
  double initial_radius_factor = 100.0;
  // MINPACK's ftol: relative reductions of ‖F‖₂² below which a least-squares run has converged.
  double function_tolerance = 1e-10;
  // MINPACK's gtol: max_j |cos(F, J e_j)| at or below which the gradient vanishes (0: only an
  // exactly orthogonal F stops).
  double gradient_tolerance = 1e-12;
  // Geodesic acceleration ([TS12]): off by default (one more evaluation per step).
  bool geodesic_acceleration = false;
  double acceleration_ratio = 0.75;     // α: take v + a/2 only when 2‖Da‖ ≤ α‖Dv‖; > 0
  double second_derivative_step = 0.1;  // h of the directional second difference; > 0
  // Used only when the problem carries no Jacobian.
  FiniteDifference finite_difference = FiniteDifference::kCentral;
  // The step's linear algebra on a problem with a sparse Jacobian (run-time size): "auto" or
  // "cholmod" — the damped normal equations by CHOLMOD's sparse Cholesky — or "dense" (J dense,
  // QR with column pivoting, as on every other problem). A problem without a sparse Jacobian
  // takes the dense path whatever this says.
  std::string linear_solver = "auto";

  // Throws InvalidInput naming the field, its value and the requirement (options_validation.hpp).
  void validate() const;
  // The engine as the registry lists it, the spec keys (field names; older ones as aliases) and
  // their reading over these values (src/options/levenberg_marquardt_options.cpp).
  static EngineDescription describe();
  void read(EngineSpecReader& spec);
};

template <int N = Dynamic>
class LevenbergMarquardtEngine : public Engine<N> {
 public:
  using Options = LevenbergMarquardtOptions;

  explicit LevenbergMarquardtEngine(LevenbergMarquardtOptions lm = {}, SolverOptions options = {});

  std::string_view name() const override { return "levenberg-marquardt"; }
  const LevenbergMarquardtOptions& lm_options() const { return lm_; }
  bool least_squares() const override { return true; }
  bool accepts_bounds() const override { return true; }
  bool accepts_strict_bounds() const override { return true; }
  bool accepts_scaling() const override { return true; }
  bool has_sparse_path() const override { return lm_.linear_solver != "dense"; }

  // Square: F = G − x, J = ∂G − I.
  Summary solve(const FixedPointProblem<N>& problem, Vector<N>& x) override;
  // Any m ≥ n.
  Summary solve_least_squares(const RootProblem<N, Dynamic>& problem, Vector<N>& x) override;

 private:
  using ResidualVector = Vector<Dynamic>;

  // The iteration on F given as residual(x, f) → finite? and jacobian(x, f, J) (evaluations it
  // spent, J the model's), with the step's linear algebra by `model`; m = rows of F.
  // jacobian_cost: the evaluations of F one Jacobian spends (0 when the problem carries one).
  template <typename Model, typename Residual, typename Jacobian>
  Summary run(Model& model, Residual&& residual, Jacobian&& jacobian, int jacobian_cost, Index m,
              Vector<N>& x);
  // The run on the sparse path (LmNormalEquationsModel, made afresh for each solve: copies of
  // an engine never share one) when the problem has a sparse Jacobian at x and linear_solver is
  // not "dense"; nullopt for the dense path.
  template <typename Problem, typename Residual>
  std::optional<Summary> run_sparse(const Problem& problem, Residual& residual, Index m,
                                    Vector<N>& x);

  void resize(Index n, Index m);
  void on_set_bounds() override {
    if (lm_.geodesic_acceleration && !this->bounds_.empty()) {
      throw InvalidInput(
          "levenberg-marquardt: geodesic acceleration does not take bounds (its "
          "second-difference point may leave the box)");
    }
  }

  LevenbergMarquardtOptions lm_;
  Vector<N> x_ = zero_vector<N>(), xt_ = zero_vector<N>(), p_ = zero_vector<N>(),
            diag_ = zero_vector<N>(), v_ = zero_vector<N>(), a_ = zero_vector<N>(),
            g_ = zero_vector<N>(), column_norms_ = zero_vector<N>(), gradient_ = zero_vector<N>();
  Eigen::Array<bool, N, 1> frozen_;
  ResidualVector f_, ft_, fh_, fp_, fm_, work_m_;
  detail::LmQrModel<N> dense_;
  Matrix<N, N> square_jacobian_;  // ∂G or ∂F of a fixed-size square problem, before J
  FiniteDifferenceWorkspace<N> fd_;
  detail::SolveLedger<N> ledger_;  // counts, budget, progress window, box
};

template <int N>
LevenbergMarquardtEngine<N>::LevenbergMarquardtEngine(LevenbergMarquardtOptions lm,
                                                      SolverOptions options)
    : Engine<N>(std::move(options)), lm_(std::move(lm)) {
  lm_.validate();
  detail::require_lipschitz_for_error_bound(name(), this->options_.stop);
}

template <int N>
void LevenbergMarquardtEngine<N>::resize(Index n, Index m) {
  if constexpr (N == Dynamic) {
    for (Vector<N>* v : {&x_, &xt_, &p_, &diag_, &v_, &a_, &g_, &column_norms_, &gradient_}) {
      v->resize(n);
    }
    frozen_.resize(n);
    fd_.resize(n);
  }
  for (ResidualVector* v : {&f_, &ft_, &fh_, &fp_, &fm_, &work_m_}) {
    if (v->size() != m) v->resize(m);
  }
}

template <int N>
template <typename Problem, typename Residual>
std::optional<Summary> LevenbergMarquardtEngine<N>::run_sparse(const Problem& problem,
                                                               Residual& residual, Index m,
                                                               Vector<N>& x) {
  if constexpr (N == Dynamic) {
    if (lm_.linear_solver == "dense") return std::nullopt;
    if constexpr (std::is_same_v<Problem, FixedPointProblem<N>>) {
      if (!problem.has_residual() || problem.sparse_residual_jacobian(x) == nullptr) {
        return std::nullopt;
      }
    } else if (problem.sparse_jacobian(x) == nullptr) {
      return std::nullopt;
    }
    detail::SparseJacobianState& state = *problem.sparse_jacobian_state();
    auto jacobian = [&state](const Vector<N>& at, const ResidualVector& f, SparseJacobian& jac) {
      return detail::evaluate_sparse_jacobian(state, at, f, jac);
    };
    detail::LmNormalEquationsModel model;
    return run(model, residual, jacobian, state.get()->evaluations_per_jacobian, m, x);
  } else {
    static_cast<void>(problem), static_cast<void>(residual), static_cast<void>(m),
        static_cast<void>(x);
    return std::nullopt;
  }
}

template <int N>
template <typename Model, typename Residual, typename Jacobian>
Summary LevenbergMarquardtEngine<N>::run(Model& model, Residual&& residual, Jacobian&& jacobian,
                                         int jacobian_cost, Index m, Vector<N>& x) {
  const Index n = x.size();
  const bool least_squares = m > n;
  StopCriteria stop = this->options_.stop;
  stop.stagnation_patience = 0;  // a trust region grows and shrinks its steps by design
  resize(n, m);
  model.resize(n, m);
  Summary summary;
  summary.engine = name();
  StopMonitor monitor(stop, x.template lpNorm<Eigen::Infinity>(), /*estimate_lipschitz=*/false);
  const double eps = std::numeric_limits<double>::epsilon();
  auto evaluate = [&](const Vector<N>& at, ResidualVector& out) {
    const bool finite = residual(at, out);
    ledger_.count_evaluation(finite ? out.stableNorm() : std::numeric_limits<double>::infinity());
    return finite;
  };
  const detail::Box<N>& box = ledger_.box();

  x_ = x;
  std::optional<Status> status;
  if (!evaluate(x_, f_)) {
    status = Status::kNonFinite;
  } else if (detail::solved_at_start<Dynamic>(f_, stop)) {
    status = Status::kConverged;
  }
  double fnorm = f_.stableNorm();  // overflow-safe, as MINPACK's enorm
  double delta = 0.0, xnorm = 0.0, lambda = 0.0, last_step = 0.0;
  bool accepted_any = false;  // until the first accepted step Δ ≤ ‖Dp‖ (MINPACK's iter = 1)
  // A square system stuck where a bound holds x against −∇(½‖F‖²) = −Jᵀ F is blocked.
  auto stagnate = [&](std::string why) {
    if (const std::optional<Index> i = box.blocking(x_, gradient_, detail::BoxMove::kDirection)) {
      summary.message = box.blocked_message(*i, x_, f_.template lpNorm<Eigen::Infinity>(),
                                            "the descent direction");
      status = Status::kBlockedByBound;
      return;
    }
    summary.message = std::move(why);
    status = Status::kStagnated;
  };
  // The budget is spent, or the progress window passed without progress (stagnated, or blocked
  // where a bound holds x against the descent direction −Jᵀ F, unless ‖F‖∞ is already usable):
  // status set.
  auto spent = [&] {
    if (ledger_.budget_spent()) {
      status = ledger_.spent_status(summary.message, x_, gradient_,
                                    f_.template lpNorm<Eigen::Infinity>());
    }
    return status.has_value();
  };

  while (!status) {
    if (spent()) break;
    if (!ledger_.affords(jacobian_cost)) {
      status = Status::kMaxEvaluations;  // the differences would overrun the budget
      break;
    }
    ledger_.count_jacobian(jacobian(x_, f_, model.jacobian()));
    if (!model.finite()) {
      summary.message = "the Jacobian of F is not finite";
      status = Status::kNonFinite;
      break;
    }
    // −∇(½‖F‖²) = −Jᵀ F; in a box, the active set: the variables on a closed bound it points out
    // of are frozen for this Jacobian (their columns zeroed, so the step leaves them where they
    // are). A strict bound is never reached: its steps are cut short by the projection instead.
    model.gradient(f_, gradient_);
    frozen_.setConstant(false);
    if (box.active()) {
      for (Index k = 0; k < n; ++k)
        frozen_[k] = box.on_closed_bound_against(k, x_[k], gradient_[k]);
    }
    const bool bound_held = frozen_.any();
    model.freeze(frozen_);
    model.column_norms(column_norms_);
    if (!column_norms_.allFinite()) {
      // (Entries near 1e154: every cosine would read 0 and gtol stop a run far from a minimum.)
      summary.message = "the column norms of the Jacobian of F overflow";
      status = Status::kNonFinite;
      break;
    }
    if (ledger_.jacobians() == 1) {
      if (lm_.scale_by_jacobian_columns) {
        for (Index j = 0; j < n; ++j) diag_[j] = column_norms_[j] == 0.0 ? 1.0 : column_norms_[j];
      } else {
        diag_.setOnes();
      }
      xnorm = diag_.cwiseProduct(x_).norm();
      delta = xnorm > 0.0 ? lm_.initial_radius_factor * xnorm : lm_.initial_radius_factor;
    } else if (lm_.scale_by_jacobian_columns) {
      diag_ = diag_.cwiseMax(column_norms_);
    }
    // MINPACK's gtol: the largest cosine between F and a column of J (in a box, of the free
    // variables' columns: the frozen ones are zero).
    const double cosine = model.factor(f_, fnorm, diag_, column_norms_);
    if (cosine <= lm_.gradient_tolerance) {
      if (least_squares) {
        summary.message = bound_held ? "the projected gradient vanishes: a minimum on the box"
                                     : "the gradient vanishes: cos(F, J e_j) <= gradient_tolerance";
        status = Status::kConverged;
      } else {
        stagnate("a local minimum of |F| that is not a root: J^T F = 0");
      }
      break;
    }

    // Inner loop: trial steps with this Jacobian until one is accepted.
    while (!status) {
      lambda = model.find_lambda(delta, lambda, v_);
      const double vnorm = diag_.cwiseProduct(v_).norm();
      if (!std::isfinite(lambda) || !v_.allFinite()) {
        stagnate("the Levenberg-Marquardt step is not finite (J or F near overflow)");
        break;
      }
      if (!accepted_any) delta = std::min(delta, vnorm);
      if (spent()) break;
      p_ = v_;
      bool accelerated = false;
      if (lm_.geodesic_acceleration) {
        // r_vv ≈ (2/h)((F(x + h v) − F(x))/h − J v); a = −(JᵀJ + λD²)⁻¹ Jᵀ r_vv.
        const double h = lm_.second_derivative_step;
        xt_ = x_ + h * v_;
        // A probe for F'', not a point of the path: it counts towards the progress window but
        // is never progress.
        ledger_.count_evaluation(std::numeric_limits<double>::infinity());
        if (residual(xt_, fh_)) {
          model.multiply(v_, work_m_);
          work_m_ = (2.0 / h) * ((fh_ - f_) / h - work_m_);
          model.damped_solve(lambda, work_m_, a_);
          if (2.0 * diag_.cwiseProduct(a_).norm() <= lm_.acceleration_ratio * vnorm) {
            p_ = v_ + 0.5 * a_;
            accelerated = true;
          }
        }
        if (spent()) break;
      }
      // The radius follows the model's own step, as dogleg's: one the box cut short says
      // nothing against the model (near a strict bound each cut is 99 % of the room left).
      const double model_pnorm = diag_.cwiseProduct(p_).norm();
      xt_ = x_ + p_;
      const bool projected = box.project(xt_, x_);
      if (projected) p_ = xt_ - x_;
      const double pnorm = diag_.cwiseProduct(p_).norm();
      if (projected && pnorm == 0.0) {
        // The box holds x against this step: no evaluation; a smaller radius (a larger λ) turns
        // the step towards −Jᵀ F.
        delta *= 0.5;
        if (delta > eps * xnorm) continue;
        stagnate("the trust radius fell below machine precision relative to |x|");
        break;
      }
      const bool finite = evaluate(xt_, ft_);
      const double fnorm_trial =
          finite ? ft_.stableNorm() : std::numeric_limits<double>::infinity();
      const double actual =
          0.1 * fnorm_trial < fnorm ? 1.0 - std::pow(fnorm_trial / fnorm, 2) : -1.0;
      // Predicted reduction of the linear model: for the velocity v, Moré's formula; for a
      // projected step p', 1 − ‖F + J p'‖²/‖F‖² directly. directional = Fᵀ J p / ‖F‖².
      double predicted = 0.0, directional = 0.0;
      if (projected) {
        model.multiply(p_, work_m_);
        directional = f_.dot(work_m_) / (fnorm * fnorm);
        predicted = -2.0 * directional - work_m_.squaredNorm() / (fnorm * fnorm);
      } else {
        model.multiply(v_, work_m_);
        const double t1 = work_m_.norm() / fnorm;
        const double t2 = std::sqrt(lambda) * vnorm / fnorm;
        predicted = t1 * t1 + 2.0 * t2 * t2;
        directional = -(t1 * t1 + t2 * t2);
      }
      const double ratio = predicted != 0.0 ? actual / predicted : 0.0;

      if (!(ratio > 0.25)) {  // (a NaN ratio shrinks too)
        double shrink = actual >= 0.0 ? 0.5 : 0.5 * directional / (directional + 0.5 * actual);
        if (0.1 * fnorm_trial >= fnorm || shrink < 0.1) shrink = 0.1;
        delta = shrink * std::min(delta, model_pnorm / 0.1);
        lambda /= shrink;
      } else if (lambda == 0.0 || ratio >= 0.75) {
        delta = model_pnorm / 0.5;
        lambda *= 0.5;
      }
      const bool accepted = ratio >= 1e-4;
      if (accepted) {
        accepted_any = true;
        x_ = xt_;
        std::swap(f_, ft_);
        fnorm = fnorm_trial;
        xnorm = diag_.cwiseProduct(x_).norm();
        last_step = p_.template lpNorm<Eigen::Infinity>();
        // A step with λ = 0 is the Gauss–Newton step: its size measures the distance to a
        // solution; a damped one does not.
        if (auto s = monitor.update(last_step, f_.template lpNorm<Eigen::Infinity>(),
                                    x_.template lpNorm<Eigen::Infinity>(),
                                    lambda == 0.0 && !accelerated && !projected)) {
          status = s;
        }
        this->after_iteration(summary, status, monitor.iterations(), last_step,
                              f_.template lpNorm<Eigen::Infinity>(), x_);
        if (status) break;
        if (fnorm == 0.0) {
          status = Status::kConverged;
          break;
        }
      }
      if (std::abs(actual) <= lm_.function_tolerance && predicted <= lm_.function_tolerance &&
          0.5 * ratio <= 1.0) {
        if (least_squares) {
          summary.message = "relative reduction of |F|^2 <= function_tolerance";
          status = Status::kConverged;
        } else {
          stagnate(
              "no relative reduction of |F|^2 above function_tolerance: a local minimum "
              "of |F| that is not a root");
        }
        break;
      }
      if (delta <= eps * xnorm) {
        stagnate("the trust radius fell below machine precision relative to |x|");
        break;
      }
      if (accepted) break;  // a new Jacobian at the new point
    }
  }

  x = x_;
  ledger_.finish(summary, *status, monitor, x, f_, this->options_.stop, least_squares);
  model.report(summary);
  return summary;
}

template <int N>
Summary LevenbergMarquardtEngine<N>::solve(const FixedPointProblem<N>& problem, Vector<N>& x) {
  if (std::optional<Summary> scaled = this->solve_scaled(*this, problem, x)) {
    return std::move(*scaled);
  }
  detail::check_initial_guess(name(), problem, x);
  ledger_.start(name(), this->bounds_, x, this->options_.stop);
  const Index n = x.size();
  auto residual = [&](const Vector<N>& at, ResidualVector& f) {
    if (problem.has_residual()) {  // F itself, not G − x (problem.hpp)
      problem.residual(at, g_);
      detail::check_output_size(problem, g_);
      f = g_;
    } else {
      problem.evaluate(at, g_);
      detail::check_output_size(problem, g_);
      f = g_ - at;
    }
    return f.allFinite();
  };
  if (std::optional<Summary> sparse = run_sparse(problem, residual, n, x)) {
    return std::move(*sparse);
  }
  // ∂G or ∂F straight into J at run-time size; through square_jacobian_ at a fixed one (J is
  // m×n there, Matrix<Dynamic, N>).
  auto jacobian = [&](const Vector<N>& at, const ResidualVector& f,
                      typename detail::LmQrModel<N>::JacobianMatrix& jac) {
    Matrix<N, N>& square = [&]() -> Matrix<N, N>& {
      if constexpr (N == Dynamic) {
        return jac;
      } else {
        return square_jacobian_;
      }
    }();
    int spent = 0;
    if (problem.has_jacobian() && problem.has_residual()) {
      problem.residual_jacobian(at, square);  // ∂F itself
    } else {
      if (problem.has_jacobian()) {
        problem.jacobian(at, square);
      } else {
        xt_ = f + at;  // G(x)
        spent = finite_difference_jacobian(problem, at, xt_, square, lm_.finite_difference, fd_,
                                           &ledger_.box());
      }
      square.diagonal().array() -= 1.0;
    }
    if constexpr (N != Dynamic) jac = square;
    return spent;
  };
  const int cost = problem.has_jacobian() ? 0 : finite_difference_cost(lm_.finite_difference, n);
  return run(dense_, residual, jacobian, cost, n, x);
}

template <int N>
Summary LevenbergMarquardtEngine<N>::solve_least_squares(const RootProblem<N, Dynamic>& problem,
                                                         Vector<N>& x) {
  if (!this->scaling_.empty()) {
    // A scaling is KINSOL's, of a square system: solved as one (Engine::solve_least_squares
    // builds it and solve() scales it); for m > n weight the residuals in F instead.
    if (problem.residual_size() == problem.size())
      return Engine<N>::solve_least_squares(problem, x);
    std::ostringstream os;
    os << name() << ": a scaling (u_scale, f_scale) applies to square systems; F maps R^"
       << problem.size() << " to R^" << problem.residual_size()
       << " (weight its residuals in F instead)";
    throw InvalidInput(os.str());
  }
  detail::check_initial_guess<N>(name(), problem.size(), x);
  const Index m = problem.residual_size();
  // A least-squares minimum has ‖F‖ > 0 and a warm start may sit at it: no progress window there
  // (its stop is function_tolerance's, a convergence).
  ledger_.start(name(), this->bounds_, x, this->options_.stop,
                /*progress_window=*/m == problem.size());
  if (m < problem.size()) {
    std::ostringstream os;
    os << name() << ": F maps R^" << problem.size() << " to R^" << m
       << "; Levenberg-Marquardt needs at least as many residuals as unknowns";
    throw InvalidInput(os.str());
  }
  auto residual = [&](const Vector<N>& at, ResidualVector& f) {
    problem.evaluate(at, f);
    if (f.size() != m) {
      std::ostringstream os;
      os << "F returned a vector of size " << f.size() << ", expected " << m;
      throw InvalidInput(os.str());
    }
    return f.allFinite();
  };
  if (std::optional<Summary> sparse = run_sparse(problem, residual, m, x)) {
    return std::move(*sparse);
  }
  auto jacobian = [&](const Vector<N>& at, const ResidualVector& f,
                      typename detail::LmQrModel<N>::JacobianMatrix& jac) {
    if (problem.has_jacobian()) {
      problem.jacobian(at, jac);
      return 0;
    }
    return finite_difference_jacobian<N, Dynamic>(
        [&problem](const Vector<N>& p, ResidualVector& out) { problem.evaluate(p, out); }, at, f,
        jac, lm_.finite_difference, fd_, fp_, fm_, &ledger_.box());
  };
  const int cost =
      problem.has_jacobian() ? 0 : finite_difference_cost(lm_.finite_difference, problem.size());
  return run(dense_, residual, jacobian, cost, m, x);
}

// Compiled once in the library for its sizes (nlobs/solvers/library_sizes.hpp).
#define NLOBS_EXTERN_LM_ENGINE(n) extern template class LevenbergMarquardtEngine<n>;
NLOBS_FOR_EACH_LIBRARY_SIZE(NLOBS_EXTERN_LM_ENGINE)
#undef NLOBS_EXTERN_LM_ENGINE

}  // namespace nlobs
