#pragma once
// The β problem of the MVT observer ([BMH]). For a pair (x̂, ê) the mean value
// theorem gives, row by row,
//     F_i(x̂ + ê) − F_i(x̂) = ∇F_i(x̂ + β_i ê) · ê   for some β_i ∈ [0, 1],
// so the residual X_i(β_i) = F_i(x̂ + ê) − F_i(x̂) − ∇F_i(x̂ + β_i ê) · ê has a root in [0, 1]
// and the MVT Jacobian D (row i = ∇F_i(x̂ + β_i ê)) satisfies D ê = F(x̂ + ê) − F(x̂) exactly.
// The paper minimises ‖X(β)‖₂ over the box [0, 1]ⁿ; since X_i depends on β_i only, the rows
// decouple and the minimum is 0. Three solvers, chosen by name:
//   per-row  a scalar bounded root search per row: secant steps from the previous β_i, then a
//            bracketing search (Boost.Math TOMS 748) or, for a root that touches zero without a
//            sign change, Brent's minimiser of |X_i| (Boost.Math);
//   nlopt    the joint problem min ½‖X(β)‖² on [0, 1]ⁿ through NloptEngine (the paper's choice);
//   ceres    the same through CeresEngine with bounds.
// The joint solvers get ∂X/∂β = diag(X_i'(β_i)) from two evaluations of X (central differences
// with every β_i perturbed at once — exact for a diagonal Jacobian).
#include <boost/math/tools/minima.hpp>
#include <boost/math/tools/toms748_solve.hpp>
#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "nlobs/observers/core/model_derivatives.hpp"
#include "nlobs/observers/core/option_checks.hpp"
#include "nlobs/observers/mvt/mvt_options.hpp"
#include "nlobs/solvers/ceres_engine.hpp"
#include "nlobs/solvers/nlopt_engine.hpp"
#include "nlobs/solvers/status.hpp"

namespace nlobs {

struct MvtBetaResult {
  double residual_norm = 0.0;  // ‖X(β)‖₂ at the returned β (0 when degenerate)
  bool degenerate = false;     // ê is numerically zero: β kept, X ≡ 0
  bool converged = true;       // every row reached its tolerance
  int evaluations = 0;         // directional derivatives of F (one per row and β value)
};

template <ContinuousModel Model>
class MvtBetaSolver {
 public:
  static constexpr int N = Model::kStates;
  using State = ModelVector<double, N>;
  using Input = ModelVector<double, Model::kInputs>;
  using Jacobian = Eigen::Matrix<double, N, N>;

  // Keeps a pointer to `model`: it must outlive the solver. Not copyable (the engines' problem
  // refers to this object).
  MvtBetaSolver(const Model& model, MvtBetaOptions options)
      : derivatives_(model), options_(std::move(options)) {
    detail::require_positive("MvtBetaOptions", "tolerance", options_.tolerance);
    detail::require_at_least("MvtBetaOptions", "max_iterations",
                             static_cast<long>(options_.max_iterations), 1L);
    if (options_.method != MvtBetaMethod::kPerRow) make_engine();
  }
  MvtBetaSolver(const MvtBetaSolver&) = delete;
  MvtBetaSolver& operator=(const MvtBetaSolver&) = delete;

  const MvtBetaOptions& options() const { return options_; }
  const ModelDerivatives<Model>& derivatives() const { return derivatives_; }

  // Freezes the pair (x̂, ê), u and t, and evaluates F(x̂) and F(x̂ + ê). False when either is
  // not finite (the caller reports it; nothing else is evaluated).
  bool set_pair(const State& xhat, const State& ehat, const Input& u, double t) {
    xhat_ = xhat;
    ehat_ = ehat;
    u_ = u;
    t_ = t;
    f_xhat_ = derivatives_.value(xhat_, u_, t_);
    f_w_ = derivatives_.value(State(xhat_ + ehat_), u_, t_);
    delta_ = f_w_ - f_xhat_;
    // ê is numerically zero when x̂ + ê rounds to x̂: X ≡ 0 and β carries no information.
    degenerate_ = (xhat_ + ehat_ == xhat_);
    return f_xhat_.allFinite() && f_w_.allFinite();
  }
  const State& f_xhat() const { return f_xhat_; }  // F(x̂)
  const State& f_w() const { return f_w_; }        // F(x̂ + ê)
  bool degenerate() const { return degenerate_; }

  // X_i(β) for one row (one directional derivative of F).
  double residual_row(int i, double beta) const {
    ++evaluations_;
    return delta_[i] - derivatives_.directional(State(xhat_ + beta * ehat_), ehat_, u_, t_)[i];
  }
  // X(β), every row at its own β_i.
  void residual(const State& beta, State& x) const {
    for (int i = 0; i < N; ++i) x[i] = residual_row(i, beta[i]);
  }

  // β ∈ [0, 1]ⁿ with X(β) ≈ 0, warm-started from `beta` (entries outside [0, 1] are clamped;
  // a non-finite entry restarts at 1/2). A degenerate pair keeps `beta` as it is.
  MvtBetaResult solve(State& beta) {
    evaluations_ = 0;
    MvtBetaResult r;
    for (int i = 0; i < N; ++i) {
      beta[i] = std::isfinite(beta[i]) ? std::clamp(beta[i], 0.0, 1.0) : 0.5;
    }
    if (degenerate_) {
      r.degenerate = true;
      return r;
    }
    if (options_.method == MvtBetaMethod::kPerRow) {
      for (int i = 0; i < N; ++i) r.converged = solve_row(i, beta[i]) && r.converged;
    } else {
      solve_joint(beta);
      if (options_.polish_rows) {
        residual(beta, x_);
        for (int i = 0; i < N; ++i) {
          if (std::abs(x_[i]) > row_tolerance(i)) solve_row(i, beta[i]);
        }
      }
    }
    residual(beta, x_);
    for (int i = 0; i < N; ++i) r.converged = r.converged && std::abs(x_[i]) <= row_tolerance(i);
    r.converged = r.converged && x_.allFinite();
    r.residual_norm = x_.norm();
    r.evaluations = evaluations_;
    return r;
  }

  // D: row i = ∇F_i(x̂ + β_i ê).
  void mvt_jacobian(const State& beta, Jacobian& d) const {
    for (int i = 0; i < N; ++i) {
      derivatives_.jacobian(State(xhat_ + beta[i] * ehat_), u_, t_, j_);
      d.row(i) = j_.row(i);
    }
  }

  // |X_i| this row aims for: the option, or the rounding floor of F_i(x̂ + ê) − F_i(x̂).
  double row_tolerance(int i) const {
    const double floor =
        8.0 * std::numeric_limits<double>::epsilon() * (std::abs(f_xhat_[i]) + std::abs(f_w_[i]));
    return std::max(options_.tolerance, floor);
  }

 private:
  // Secant steps from the warm start; then a sign-change search on a grid with TOMS 748; then
  // Brent's minimiser of |X_i| (a root without a sign change). Returns whether |X_i| reached
  // the row tolerance; `beta` is the best point seen either way.
  bool solve_row(int i, double& beta) {
    const double tol = row_tolerance(i);
    double best = beta, best_x = residual_row(i, beta);
    if (std::abs(best_x) <= tol) return true;
    const auto consider = [&](double b, double x) {
      if (std::abs(x) < std::abs(best_x)) best = b, best_x = x;
      return std::abs(x) <= tol;
    };
    double b0 = beta, x0 = best_x;
    double b1 = beta + (beta < 0.5 ? 1e-3 : -1e-3);
    double x1 = residual_row(i, b1);
    if (consider(b1, x1)) return beta = best, true;
    const int secant_steps = std::min(options_.max_iterations, 12);
    for (int it = 0; it < secant_steps && x1 != x0; ++it) {
      const double b2 = std::clamp(b1 - x1 * (b1 - b0) / (x1 - x0), 0.0, 1.0);
      if (b2 == b1) break;  // pinned at a bound
      const double x2 = residual_row(i, b2);
      if (consider(b2, x2)) return beta = best, true;
      b0 = b1, x0 = x1, b1 = b2, x1 = x2;
    }
    // Grid: the sign change nearest the warm start, refined by TOMS 748.
    constexpr int kCells = 16;
    double grid_x[kCells + 1];
    for (int c = 0; c <= kCells; ++c) {
      const double b = static_cast<double>(c) / kCells;
      grid_x[c] = residual_row(i, b);
      if (consider(b, grid_x[c])) return beta = best, true;
    }
    int cell = -1;
    for (int c = 0; c < kCells; ++c) {
      if ((grid_x[c] < 0.0) != (grid_x[c + 1] < 0.0)) {
        const double mid = (c + 0.5) / kCells;
        if (cell < 0 || std::abs(mid - beta) < std::abs((cell + 0.5) / kCells - beta)) cell = c;
      }
    }
    const auto f = [this, i](double b) { return residual_row(i, b); };
    if (cell >= 0) {
      std::uintmax_t iterations = static_cast<std::uintmax_t>(options_.max_iterations);
      const auto stop = [&](double a, double b) {
        return std::abs(b - a) <= 4.0 * std::numeric_limits<double>::epsilon();
      };
      // Boost.Math reports its own failures by exception: those mean "no root refined in this
      // cell". An exception from the model inside f is the user's and goes on to the caller
      // (the observer names it), not swallowed as a failed refinement.
      std::exception_ptr from_model;
      const auto guarded = [&](double b) {
        try {
          return f(b);
        } catch (...) {
          from_model = std::current_exception();
          throw;
        }
      };
      try {
        const auto [a, b] = boost::math::tools::toms748_solve(
            guarded, static_cast<double>(cell) / kCells, static_cast<double>(cell + 1) / kCells,
            grid_x[cell], grid_x[cell + 1], stop, iterations);
        for (double root : {a, b}) consider(root, residual_row(i, root));
      } catch (const std::exception&) {  // (anything else came from the model: it goes on)
        if (from_model) std::rethrow_exception(from_model);
      }
    } else {
      std::uintmax_t iterations = static_cast<std::uintmax_t>(options_.max_iterations);
      const auto [b, x] = boost::math::tools::brent_find_minima(
          [&f](double at) { return std::abs(f(at)); }, 0.0, 1.0,
          std::numeric_limits<double>::digits / 2, iterations);
      consider(b, residual_row(i, b));
      (void)x;
    }
    beta = best;
    return std::abs(best_x) <= tol;
  }

  void solve_joint(State& beta) {
    Vector<N> b = beta;
    engine_->solve_least_squares(*problem_, b);
    if (b.allFinite()) {
      for (int i = 0; i < N; ++i) beta[i] = std::clamp(b[i], 0.0, 1.0);
    }
  }

  void make_engine() {
    SolverOptions solver;
    solver.stop.residual_tolerance = options_.tolerance;
    solver.stop.step_tolerance = 1e-15;
    solver.stop.max_iterations = options_.max_iterations;
    solver.stop.max_evaluations = 50 * options_.max_iterations;
    const Eigen::VectorXd lower = Eigen::VectorXd::Zero(N), upper = Eigen::VectorXd::Ones(N);
    if (options_.method == MvtBetaMethod::kNlopt) {
      NloptOptions nlopt;
      nlopt.algorithm = options_.nlopt_algorithm;
      nlopt.lower_bounds = lower;
      nlopt.upper_bounds = upper;
      auto engine = std::make_unique<NloptEngine<N>>(nlopt, solver);
      if (!engine->needs_gradient()) {
        throw InvalidInput("MvtBetaOptions::nlopt_algorithm = '" + options_.nlopt_algorithm +
                           "': choose a gradient-based (LD_*) algorithm; X's derivative is cheap");
      }
      engine_ = std::move(engine);
    } else {
      CeresOptions ceres;
      ceres.lower_bounds = lower;
      ceres.upper_bounds = upper;
      ceres.function_tolerance = 0.0;
      ceres.gradient_tolerance = 0.0;
      engine_ = std::make_unique<CeresEngine<N>>(ceres, solver);
    }
    problem_.emplace(RootProblem<N, Dynamic>::with_jacobian(
        [this](const Vector<N>& beta, Eigen::VectorXd& x) {
          residual(beta, x_);
          x = x_;
        },
        [this](const Vector<N>& beta, Matrix<Dynamic, N>& jac) {
          // X_i depends on β_i only: perturbing every β_i at once gives the whole diagonal.
          constexpr double h = 1e-6;
          residual(State(beta.array() + h), xp_);
          residual(State(beta.array() - h), xm_);
          jac.setZero();
          jac.diagonal() = (xp_ - xm_) / (2.0 * h);
        },
        N, N));
  }

  ModelDerivatives<Model> derivatives_;
  MvtBetaOptions options_;
  State xhat_ = State::Zero(), ehat_ = State::Zero(), f_xhat_ = State::Zero(), f_w_ = State::Zero(),
        delta_ = State::Zero();
  Input u_ = Input::Zero();
  double t_ = 0.0;
  bool degenerate_ = true;
  mutable State x_ = State::Zero(), xp_ = State::Zero(), xm_ = State::Zero();
  mutable Jacobian j_ = Jacobian::Zero();
  mutable int evaluations_ = 0;
  std::unique_ptr<Engine<N>> engine_;
  std::optional<RootProblem<N, Dynamic>> problem_;
};

}  // namespace nlobs
