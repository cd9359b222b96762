#pragma once
// Newton's method on F(x) = G(x) − x (for a root problem adapted with Ψ = I this is F itself;
// on the window problem it is the Moraal–Grizzle observer, [MG95]:
// w ← w + (∂H/∂w)⁻¹ (Y − H(w))). The Jacobian J = ∂G − I comes from the problem (user-supplied
// or AD) or from finite differences. Optional backtracking line search on ½‖F‖₂² (Armijo).
// Or a trust-region globalisation: the dogleg step between the Newton and the Cauchy step in
// ‖p‖₂ ≤ Δ, a fresh Jacobian at every iterate (DoglegEngine without Broyden updates, whose
// radius rules and stop tests it shares).
// The residual at the returned point is always known: no extra evaluation.
// Bounds (Engine::set_bounds): the step is projected onto the box, x ← P(x + t Δx); with a line
// search the Armijo test takes the projected step, and when the Newton path finds no decrease the
// projected steepest-descent path of ½‖F‖² is searched from its Cauchy point. A point where a
// bound holds x against the descent direction and neither path decreases ‖F‖ ends the run
// blocked_by_bound (without a line search: where the projected Newton step is zero).
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <string_view>
#include <utility>

#include "nlobs/solvers/dogleg_engine.hpp"
#include "nlobs/solvers/engine.hpp"
#include "nlobs/solvers/finite_difference.hpp"
#include "nlobs/solvers/library_sizes.hpp"
#include "nlobs/solvers/square_system.hpp"
#include "nlobs/solvers/stop_monitor.hpp"

namespace nlobs {

struct NewtonOptions {
  bool line_search = false;
  // Trust region instead (not with line_search): DoglegOptions' defaults, broyden_updates off.
  bool trust_region = false;
  double sufficient_decrease = 1e-4;  // Armijo c ∈ (0, 0.5)
  double backtrack_factor = 0.5;      // t ← factor · t, factor ∈ (0, 1)
  int max_backtracks = 30;            // ≥ 1
  // Used only when the problem carries no Jacobian.
  FiniteDifference finite_difference = FiniteDifference::kCentral;
};

template <int N = Dynamic>
class NewtonEngine : public Engine<N> {
 public:
  explicit NewtonEngine(NewtonOptions newton = {}, SolverOptions options = {})
      : Engine<N>(std::move(options)), newton_(newton) {
    auto fail = [](const char* option, double value, const char* requirement) {
      std::ostringstream os;
      os << "NewtonOptions::" << option << " = " << value << " is invalid: " << requirement;
      throw InvalidInput(os.str());
    };
    if (!(newton_.sufficient_decrease > 0.0 && newton_.sufficient_decrease < 0.5)) {
      fail("sufficient_decrease", newton_.sufficient_decrease, "must lie in (0, 0.5)");
    }
    if (!(newton_.backtrack_factor > 0.0 && newton_.backtrack_factor < 1.0)) {
      fail("backtrack_factor", newton_.backtrack_factor, "must lie in (0, 1)");
    }
    if (newton_.max_backtracks < 1) fail("max_backtracks", newton_.max_backtracks, "must be >= 1");
    if (newton_.line_search && newton_.trust_region) {
      throw InvalidInput(
          "NewtonOptions: line_search and trust_region are two globalisations; "
          "choose one");
    }
    detail::require_lipschitz_for_error_bound(name(), this->options_.stop);
    if (newton_.trust_region) {
      trust_region_.emplace(
          DoglegOptions{.broyden_updates = false, .finite_difference = newton_.finite_difference},
          this->options_);
    }
  }

  std::string_view name() const override { return "newton"; }
  const NewtonOptions& newton_options() const { return newton_; }
  bool accepts_bounds() const override { return true; }
  bool accepts_strict_bounds() const override { return true; }
  bool accepts_scaling() const override { return true; }

  Summary solve(const FixedPointProblem<N>& problem, Vector<N>& x) override;

 private:
  void on_limit_evaluations(int max_evaluations) override {
    if (trust_region_) trust_region_->limit_evaluations(max_evaluations);
  }
  void on_set_bounds() override {
    if (trust_region_) trust_region_->set_bounds(this->bounds_);
  }
  void on_set_scaling() override {
    if (trust_region_) trust_region_->set_scaling(this->scaling_);
  }
  NewtonOptions newton_;
  std::optional<DoglegEngine<N>> trust_region_;
  detail::SquareSystem<N> system_;
  Vector<N> x_ = zero_vector<N>(), f_ = zero_vector<N>(), dx_ = zero_vector<N>(),
            xt_ = zero_vector<N>(), ft_ = zero_vector<N>(), gradient_ = zero_vector<N>();
  Matrix<N, N> jac_;
  // Partial pivoting (3–4× cheaper than full pivoting at n = 3); a pivot below this fraction
  // of the largest |J_ij| is treated as a zero pivot: the Newton step would be meaningless.
  static constexpr double kSingularPivot = 1e-13;
  Eigen::PartialPivLU<Matrix<N, N>> lu_;
};

template <int N>
Summary NewtonEngine<N>::solve(const FixedPointProblem<N>& problem, Vector<N>& x) {
  if (trust_region_) {
    Summary s = trust_region_->solve(problem, x);
    s.engine = name();
    return s;
  }
  if (std::optional<Summary> scaled =
          this->solve_scaled(problem, x, [this](const FixedPointProblem<N>& p, Vector<N>& y) {
            return NewtonEngine<N>::solve(p, y);
          })) {
    return std::move(*scaled);
  }
  const StopCriteria& stop = this->options_.stop;
  system_.start(name(), problem, x, this->bounds_, newton_.finite_difference, stop);
  const detail::Box<N>& box = system_.box();
  const Index n = x.size();
  if constexpr (N == Dynamic) {
    for (Vector<N>* v : {&x_, &f_, &dx_, &xt_, &ft_, &gradient_}) v->resize(n);
    jac_.resize(n, n);
    if (lu_.rows() != n) lu_ = Eigen::PartialPivLU<Matrix<N, N>>(n);
  }
  Summary summary;
  summary.engine = name();
  StopMonitor monitor(stop, x.template lpNorm<Eigen::Infinity>(), /*estimate_lipschitz=*/false);

  // Backtracking along the projected path P(x + t d), t = t0, t0·factor, …: the first t with
  // ‖F(x_t)‖₂² ≤ ‖F(x)‖₂² + 2c ∇φᵀ(x_t − x), φ = ½‖F‖₂², ∇φ = J_Fᵀ F (Armijo). For the Newton
  // direction without a box ∇φᵀ t d = −t‖F‖₂², the test in its usual form. With armijo = false,
  // the first finite trial. x_t in xt_, F(x_t) in ft_; false when none, or when the box holds x
  // in place (held_in_place).
  bool projected = false, held_in_place = false;
  double t = 1.0;
  auto search = [&](const Vector<N>& d, double t0, bool armijo) {
    const double phi0 = f_.squaredNorm();
    t = t0;
    for (int k = 0; k <= newton_.max_backtracks && !system_.budget_spent(); ++k) {
      xt_ = x_ + t * d;
      projected = box.project(xt_, x_);
      held_in_place = projected && xt_ == x_;
      if (held_in_place) return false;  // every component that would move is held
      const bool finite = system_.residual(xt_, ft_);
      if (!armijo) return finite;
      const double decrease = projected || box.active()
                                  ? -2.0 * newton_.sufficient_decrease * gradient_.dot(xt_ - x_)
                                  : 2.0 * newton_.sufficient_decrease * t * phi0;
      // (A projected Newton path need not descend: ∇φᵀ(x_t − x) > 0 still allows no increase.)
      if (finite && ft_.squaredNorm() <= std::min(phi0 - decrease, phi0)) return true;
      t *= newton_.backtrack_factor;
    }
    return false;
  };

  x_ = x;
  std::optional<Status> status;
  if (!system_.residual(x_, f_)) {
    status = Status::kNonFinite;
  } else if (detail::solved_at_start(f_, stop)) {
    status = Status::kConverged;
  }
  double fnorm = f_.template lpNorm<Eigen::Infinity>();

  while (!status) {
    if (system_.budget_spent()) {
      // −∇φ at the last Jacobian: what a bound may hold (the window needs one to expire).
      if (box.active() && system_.jacobians() > 0) dx_ = -gradient_;
      status = system_.spent_status(summary.message, x_, dx_, fnorm);
      break;
    }
    if ((status = system_.jacobian(x_, f_, jac_, summary.message))) break;
    lu_.compute(jac_);
    const double smallest_pivot = lu_.matrixLU().diagonal().cwiseAbs().minCoeff();
    if (!(smallest_pivot > kSingularPivot * jac_.cwiseAbs().maxCoeff())) {
      std::ostringstream os;
      os << "Jacobian of F is singular at iteration " << monitor.iterations() + 1
         << " (smallest LU pivot " << smallest_pivot << ")";
      summary.message = os.str();
      status = Status::kSingularJacobian;
      break;
    }
    dx_ = lu_.solve(f_);
    dx_ = -dx_;
    if (!dx_.allFinite()) {
      summary.message = "Newton step is not finite (Jacobian numerically singular)";
      status = Status::kSingularJacobian;
      break;
    }
    if (box.active()) gradient_.noalias() = jac_.transpose() * f_;

    // The Newton step (backtracked with a line search); in a box, when that finds no decrease,
    // the projected steepest-descent path from the Cauchy point of the linear model.
    bool descent_step = false;
    bool accepted = search(dx_, 1.0, newton_.line_search);
    if (!accepted && newton_.line_search && box.active() && !system_.budget_spent()) {
      const double curvature = (jac_ * gradient_).squaredNorm();
      if (curvature > 0.0) {
        dx_ = -gradient_;
        accepted = search(dx_, gradient_.squaredNorm() / curvature, true);
        descent_step = true;
      }
    }
    if (!accepted) {
      // Blocked: without a line search where the box holds the Newton step in place; with one
      // where neither path decreases |F| and a bound holds x against −∇φ.
      std::optional<Index> held;
      if (box.active() && (newton_.line_search || held_in_place)) {
        if (newton_.line_search) dx_ = -gradient_;
        held = box.blocking(
            x_, dx_, newton_.line_search ? detail::BoxMove::kDirection : detail::BoxMove::kStep);
      }
      if (system_.budget_spent()) {
        status = system_.spent_status(summary.message, x_, dx_, fnorm);
      } else if (held) {
        summary.message = box.blocked_message(
            *held, x_, fnorm, newton_.line_search ? "the descent direction" : "the Newton step");
        status = Status::kBlockedByBound;
      } else if (!newton_.line_search) {
        status = Status::kNonFinite;
      } else {
        summary.message = "line search found no decrease of |F|";
        status = Status::kStagnated;
      }
      break;
    }
    const double step = projected ? (xt_ - x_).template lpNorm<Eigen::Infinity>()
                                  : t * dx_.template lpNorm<Eigen::Infinity>();
    x_ = xt_;
    f_ = ft_;
    fnorm = f_.template lpNorm<Eigen::Infinity>();
    // A step the box cut short, or a descent step, says nothing about the distance to a root.
    status = monitor.update(step, fnorm, x_.template lpNorm<Eigen::Infinity>(),
                            !projected && !descent_step);
    if (this->options_.record_trace) {
      summary.trace.push_back({monitor.iterations(), step, fnorm, x_});
    }
  }

  x = x_;
  system_.finish(summary, *status, monitor, x, f_, stop);
  return summary;
}

// Compiled once in the library for its sizes (nlobs/solvers/library_sizes.hpp).
#define NLOBS_EXTERN_NEWTON_ENGINE(n) extern template class NewtonEngine<n>;
NLOBS_FOR_EACH_LIBRARY_SIZE(NLOBS_EXTERN_NEWTON_ENGINE)
#undef NLOBS_EXTERN_NEWTON_ENGINE

}  // namespace nlobs
