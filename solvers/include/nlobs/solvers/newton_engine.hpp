#pragma once
// Newton's method on F(x) = G(x) − x (for a root problem adapted with Ψ = I this is F itself;
// on the window problem it is the Moraal–Grizzle observer, [MG95]:
// w ← w + (∂H/∂w)⁻¹ (Y − H(w))). The Jacobian J = ∂G − I comes from the problem (user-supplied
// or AD) or from finite differences. Optional backtracking line search on ½‖F‖₂² (Armijo).
// Or a trust-region globalisation: the dogleg step between the Newton and the Cauchy step in
// ‖p‖₂ ≤ Δ, a fresh Jacobian at every iterate (DoglegEngine without Broyden updates, whose
// radius rules and stop tests it shares).
// The residual at the returned point is always known: no extra evaluation.
#include <Eigen/LU>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <string_view>

#include "nlobs/solvers/dogleg_engine.hpp"
#include "nlobs/solvers/engine.hpp"
#include "nlobs/solvers/finite_difference.hpp"
#include "nlobs/solvers/library_sizes.hpp"
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

  Summary solve(const FixedPointProblem<N>& problem, Vector<N>& x) override;

 private:
  void on_limit_evaluations(int max_evaluations) override {
    if (trust_region_) trust_region_->limit_evaluations(max_evaluations);
  }
  NewtonOptions newton_;
  std::optional<DoglegEngine<N>> trust_region_;
  Vector<N> x_ = zero_vector<N>(), g_ = zero_vector<N>(), f_ = zero_vector<N>(),
            dx_ = zero_vector<N>(), xt_ = zero_vector<N>(), ft_ = zero_vector<N>();
  Matrix<N, N> jac_;
  // Partial pivoting (3–4× cheaper than full pivoting at n = 3); a pivot below this fraction
  // of the largest |J_ij| is treated as a zero pivot: the Newton step would be meaningless.
  static constexpr double kSingularPivot = 1e-13;
  Eigen::PartialPivLU<Matrix<N, N>> lu_;
  FiniteDifferenceWorkspace<N> fd_;
};

template <int N>
Summary NewtonEngine<N>::solve(const FixedPointProblem<N>& problem, Vector<N>& x) {
  detail::check_initial_guess(name(), problem, x);
  if (trust_region_) {
    Summary s = trust_region_->solve(problem, x);
    s.engine = name();
    return s;
  }
  const StopCriteria& stop = this->options_.stop;
  const Index n = x.size();
  if constexpr (N == Dynamic) {
    x_.resize(n), g_.resize(n), f_.resize(n), dx_.resize(n), xt_.resize(n), ft_.resize(n);
    jac_.resize(n, n), fd_.resize(n);
    if (lu_.rows() != n) lu_ = Eigen::PartialPivLU<Matrix<N, N>>(n);
  }
  Summary summary;
  summary.engine = name();
  StopMonitor monitor(stop, x.template lpNorm<Eigen::Infinity>(), /*estimate_lipschitz=*/false);
  int evaluations = 0, jacobians = 0;

  // F at a point into (g, f); false when non-finite.
  auto residual_at = [&](const Vector<N>& at, Vector<N>& f) {
    problem.evaluate(at, g_);
    ++evaluations;
    detail::check_output_size(problem, g_);
    f = g_ - at;
    return f.allFinite();
  };

  x_ = x;
  std::optional<Status> status;
  if (!residual_at(x_, f_)) status = Status::kNonFinite;
  double fnorm = f_.template lpNorm<Eigen::Infinity>();
  if (!status && stop.residual_tolerance && fnorm <= *stop.residual_tolerance) {
    status = Status::kConverged;  // x0 already solves F within tolerance
  }

  while (!status) {
    if (evaluations >= stop.max_evaluations) {
      status = Status::kMaxEvaluations;
      break;
    }
    // J_F = ∂G − I.
    if (!problem.has_jacobian() &&
        evaluations + finite_difference_cost(newton_.finite_difference, n) > stop.max_evaluations) {
      status = Status::kMaxEvaluations;  // the differences would overrun the budget
      break;
    }
    if (problem.has_jacobian()) {
      problem.jacobian(x_, jac_);
    } else {
      g_ = f_ + x_;
      evaluations +=
          finite_difference_jacobian(problem, x_, g_, jac_, newton_.finite_difference, fd_);
    }
    ++jacobians;
    jac_.diagonal().array() -= 1.0;
    if (!jac_.allFinite()) {
      status = Status::kNonFinite;
      break;
    }
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

    // Full step, or backtrack until ½‖F‖₂² decreases enough: ‖F(x+t dx)‖² ≤ (1 − 2ct)‖F(x)‖².
    double t = 1.0;
    const double phi0 = f_.squaredNorm();
    bool accepted = false;
    for (int k = 0; k <= newton_.max_backtracks; ++k) {
      if (evaluations >= stop.max_evaluations) break;
      xt_ = x_ + t * dx_;
      const bool finite = residual_at(xt_, ft_);
      if (!newton_.line_search) {
        accepted = finite;
        break;
      }
      if (finite && ft_.squaredNorm() <= (1.0 - 2.0 * newton_.sufficient_decrease * t) * phi0) {
        accepted = true;
        break;
      }
      t *= newton_.backtrack_factor;
    }
    if (!accepted) {
      if (evaluations >= stop.max_evaluations) {
        status = Status::kMaxEvaluations;
      } else if (!newton_.line_search) {
        status = Status::kNonFinite;
      } else {
        summary.message = "line search found no decrease of |F|";
        status = Status::kStagnated;
      }
      break;
    }
    const double step = t * dx_.template lpNorm<Eigen::Infinity>();
    x_ = xt_;
    f_ = ft_;
    fnorm = f_.template lpNorm<Eigen::Infinity>();
    status = monitor.update(step, fnorm, x_.template lpNorm<Eigen::Infinity>());
    if (this->options_.record_trace) {
      summary.trace.push_back({monitor.iterations(), step, fnorm, x_});
    }
  }

  x = x_;
  summary.status = *status;
  summary.function_evaluations = evaluations;
  summary.jacobian_evaluations = jacobians;
  monitor.fill(summary, f_.allFinite() ? fnorm : std::numeric_limits<double>::infinity());
  summary.record_answer(x, stop);
  return summary;
}

// Compiled once in the library for its sizes (nlobs/solvers/library_sizes.hpp).
#define NLOBS_EXTERN_NEWTON_ENGINE(n) extern template class NewtonEngine<n>;
NLOBS_FOR_EACH_LIBRARY_SIZE(NLOBS_EXTERN_NEWTON_ENGINE)
#undef NLOBS_EXTERN_NEWTON_ENGINE

}  // namespace nlobs
