#pragma once
// Newton's method on F(x) = G(x) − x (for a root problem adapted with Ψ = I this is F itself;
// on the window problem it is the Moraal–Grizzle observer, [MG95]:
// w ← w + (∂H/∂w)⁻¹ (Y − H(w))). The Jacobian J = ∂G − I comes from the problem (user-supplied
// or AD) or from finite differences. Optional backtracking line search on ½‖F‖₂² (Armijo,
// LineSearch of line_search.hpp).
// Or a trust-region globalisation: the dogleg step between the Newton and the Cauchy step in
// ‖p‖₂ ≤ Δ, a fresh Jacobian at every iterate (DoglegEngine without Broyden updates, whose
// radius rules and stop tests it shares).
// The residual at the returned point is always known: no extra evaluation.
// Bounds (Engine::set_bounds): the step is projected onto the box, x ← P(x + t Δx); with a line
// search the Armijo test takes the projected step, and when the Newton path finds no decrease the
// projected steepest-descent path of ½‖F‖² is searched from its Cauchy point. A point where a
// bound holds x against the descent direction and neither path decreases ‖F‖ ends the run
// blocked_by_bound (without a line search: where the projected Newton step is zero).
// Sparse path (run-time size, a problem with a sparse Jacobian, declared by
// sparse/sparse_problem.hpp or detected at x₀ for RootProblem::with_autodiff by
// sparse/sparsity_detection.hpp's rule): J_F is assembled sparse and the step solved by
// NewtonOptions::linear_solver (nlobs/solvers/linear/); with a Krylov solver the step is inexact,
// ‖F + J_F Δx‖₂ ≤ η_k ‖F‖₂ with η_k from Eisenstat–Walker [EW96] (Newton–Krylov), and a Krylov
// solve that ends above η_k but below ‖F‖ still gives a descent direction of ‖F‖² and is taken.
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>

#include "nlobs/solvers/dogleg_engine.hpp"
#include "nlobs/solvers/engine.hpp"
#include "nlobs/solvers/engine_spec.hpp"
#include "nlobs/solvers/finite_difference.hpp"
#include "nlobs/solvers/library_sizes.hpp"
#include "nlobs/solvers/line_search.hpp"
#include "nlobs/solvers/linear/forcing_term.hpp"
#include "nlobs/solvers/linear/linear_solver.hpp"
#include "nlobs/solvers/linear/make_linear_solver.hpp"
#include "nlobs/solvers/sparse_path.hpp"
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
  // The sparse path's linear solver, a make_linear_solver spec ("klu", "gmres:preconditioner=
  // ilu0", …), or "auto" (band-lu when J's bandwidth is at most 16, kAutoBandWidth, else klu,
  // umfpack from 20 000 unknowns: choose_linear_solver), or "dense" (the dense path even for a
  // problem with a sparse Jacobian; no detection is run).
  // Read only for problems with a sparse Jacobian; the trust region is dense whatever this says.
  std::string linear_solver = "auto";
  // η_k of the Krylov solvers (ignored by the direct ones).
  ForcingTermOptions forcing{};
  // Modified Newton (KINSOL's msbset, 10 there by default): one Jacobian, with its factorisation
  // or preconditioner, serves up to this many iterations, 1 to 1000; 1 is Newton. A stale one is
  // renewed early when its step did not halve ‖F‖₂, and a line search that fails on a stale one
  // is retried with a fresh one. Not with trust_region.
  int jacobian_reuse = 1;

  // Throws InvalidInput naming the field, its value and the requirement (options_validation.hpp).
  void validate() const;
  // The engine as the registry lists it, its spec keys the field names above (line_search=1;
  // the older names are aliases: linesearch=1), and their reading over these values
  // (src/options/newton_options.cpp).
  static EngineDescription describe();
  void read(EngineSpecReader& spec);
};

template <int N = Dynamic>
class NewtonEngine : public Engine<N> {
 public:
  using Options = NewtonOptions;

  explicit NewtonEngine(NewtonOptions newton = {}, SolverOptions options = {})
      : Engine<N>(std::move(options)), newton_(std::move(newton)) {
    newton_.validate();
    forcing_ = ForcingTerm(newton_.forcing);
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
  bool has_sparse_path() const override {
    return detail::takes_sparse_path(newton_.linear_solver, dense_reason());
  }

  Summary solve(const FixedPointProblem<N>& problem, Vector<N>& x) override;

 private:
  // What sends a solve to the dense path whatever the problem carries; nullptr for nothing.
  const char* dense_reason() const {
    if (trust_region_) return "the trust region";
    return nullptr;
  }
  // dx_ = −J_F⁻¹ f_ (dense: jac_, LU; sparse: sparse_jac_, linear_), J_F evaluated at x_ when
  // `fresh`, else the last one reused (modified Newton); nullopt or the status.
  std::optional<Status> dense_step(std::string& message, int iteration, bool fresh);
  std::optional<Status> sparse_step(std::string& message, bool fresh);
  // ∇φ = J_Fᵀ f_ (φ = ½‖F‖²) into gradient_, and ‖J_F gradient_‖², at the last Jacobian.
  void merit_gradient(bool sparse);
  double merit_curvature(bool sparse) const;
  void on_limit_evaluations(int max_evaluations) override {
    if (trust_region_) trust_region_->limit_evaluations(max_evaluations);
  }
  void on_set_record_trace(bool on) override {
    if (trust_region_) trust_region_->set_record_trace(on);
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
  // Backtracks a stale Jacobian's step gets before J is renewed (modified Newton).
  static constexpr int kStaleBacktracks = 3;
  Eigen::PartialPivLU<Matrix<N, N>> lu_;
  // The sparse path (run-time size only); the linear solver is made afresh for each solve.
  SparseJacobian sparse_jac_;
  detail::SparseLinearStep linear_;
  ForcingTerm forcing_;
  Vector<N> linear_residual_ = zero_vector<N>();  // F_k + J_k (x_{k+1} − x_k), for [EW96]
};

template <int N>
std::optional<Status> NewtonEngine<N>::dense_step(std::string& message, int iteration, bool fresh) {
  if (fresh) {
    if (const std::optional<Status> status = system_.jacobian(x_, f_, jac_, message)) {
      return status;
    }
    lu_.compute(jac_);
    const double smallest_pivot = lu_.matrixLU().diagonal().cwiseAbs().minCoeff();
    if (!(smallest_pivot > kSingularPivot * jac_.cwiseAbs().maxCoeff())) {
      std::ostringstream os;
      os << "Jacobian of F is singular at iteration " << iteration + 1 << " (smallest LU pivot "
         << smallest_pivot << ")";
      message = os.str();
      return Status::kSingularJacobian;
    }
  }
  dx_ = lu_.solve(f_);
  dx_ = -dx_;
  if (!dx_.allFinite()) {
    message = "Newton step is not finite (Jacobian numerically singular)";
    return Status::kSingularJacobian;
  }
  return std::nullopt;
}

template <int N>
std::optional<Status> NewtonEngine<N>::sparse_step(std::string& message, bool fresh) {
  if constexpr (N == Dynamic) {
    if (fresh) {
      if (const std::optional<Status> status =
              system_.sparse_jacobian(x_, f_, sparse_jac_, message)) {
        return status;
      }
    }
    // (A Krylov step above η_k but below ‖F‖ is accepted: still a descent direction.)
    const LinearStatus linear = fresh ? linear_.solve(sparse_jac_, f_, dx_, forcing_.eta(), 1.0)
                                      : linear_.resolve(f_, dx_, forcing_.eta(), 1.0);
    if (const std::optional<Status> failed = linear_.failure(linear, message)) return failed;
    dx_ = -dx_;
    return std::nullopt;
  } else {
    static_cast<void>(message), static_cast<void>(fresh);
    return Status::kInvalidInput;  // unreachable: fixed sizes have no sparse path
  }
}

template <int N>
void NewtonEngine<N>::merit_gradient(bool sparse) {
  if constexpr (N == Dynamic) {
    if (sparse) {
      gradient_.noalias() = sparse_jac_.transpose() * f_;
      return;
    }
  }
  static_cast<void>(sparse);
  gradient_.noalias() = jac_.transpose() * f_;
}

template <int N>
double NewtonEngine<N>::merit_curvature(bool sparse) const {
  if constexpr (N == Dynamic) {
    if (sparse) return (sparse_jac_ * gradient_).squaredNorm();
  }
  static_cast<void>(sparse);
  return (jac_ * gradient_).squaredNorm();
}

template <int N>
Summary NewtonEngine<N>::solve(const FixedPointProblem<N>& problem, Vector<N>& x) {
  detail::refuse_dense_path_for_declared(
      name(), problem, newton_.linear_solver, dense_reason(),
      "use the line search, or NewtonOptions::linear_solver = \"dense\" for a small problem");
  if (trust_region_) {
    Summary s = trust_region_->solve(problem, x);
    s.engine = name();
    return s;
  }
  if (std::optional<Summary> scaled = this->solve_scaled(*this, problem, x)) {
    return std::move(*scaled);
  }
  const StopCriteria& stop = this->options_.stop;
  system_.start(name(), problem, x, this->bounds_, newton_.finite_difference, stop);
  const detail::Box<N>& box = system_.box();
  const Index n = x.size();
  bool sparse = false;
  if constexpr (N == Dynamic) {
    for (Vector<N>* v : {&x_, &f_, &dx_, &xt_, &ft_, &gradient_}) v->resize(n);
    const SparseJacobianSource* source =
        detail::sparse_path_source(problem, x, newton_.linear_solver, dense_reason());
    sparse = source != nullptr;
    if (sparse) {
      linear_.choose(newton_.linear_solver, *source->pattern, n);
      forcing_.restart();
    } else {
      jac_.resize(n, n);
      if (lu_.rows() != n) lu_ = Eigen::PartialPivLU<Matrix<N, N>>(n);
    }
  }
  Summary summary;
  summary.engine = name();
  StopMonitor monitor(stop, x.template lpNorm<Eigen::Infinity>(), /*estimate_lipschitz=*/false);

  // Backtracking along the projected path P(x + t d) (LineSearch: Armijo on ‖F‖₂², with the
  // slope ∇φᵀ(x_t − x), ∇φ = J_Fᵀ F, where the box may cut the path); without a line search the
  // full step, taken where F is finite. x_t in xt_, F(x_t) in ft_; false when none is accepted,
  // or when the box holds x in place (held_in_place).
  const LineSearch line_search{
      .kind = newton_.line_search ? LineSearch::Kind::kBacktracking : LineSearch::Kind::kFullStep,
      .sufficient_decrease = newton_.sufficient_decrease,
      .shrink = newton_.backtrack_factor,
      .max_backtracks = newton_.max_backtracks};
  LineSearch stale_line_search = line_search;
  stale_line_search.max_backtracks = std::min(newton_.max_backtracks, kStaleBacktracks);
  bool projected = false, held_in_place = false;
  double t = 1.0;
  // An inexact (Krylov) step has ∇φᵀΔx = −‖F‖² + Fᵀr, not −‖F‖²: the Armijo test then takes the
  // slope from ∇φ as a projected step does.
  const bool inexact = sparse && linear_.iterative();
  auto search = [&](const Vector<N>& d, double t0, const LineSearch& rule) {
    const double phi0 = f_.squaredNorm();
    detail::ResidualPath<N> path(system_, x_, phi0, d, gradient_, box.active() || inexact, xt_,
                                 ft_);
    const LineSearch::Result result = rule.search(path, t0, phi0);
    t = result.t;
    projected = path.projected();
    held_in_place = result.outcome == LineSearch::Outcome::kHeld;
    return result.accepted();
  };

  x_ = x;
  std::optional<Status> status = system_.first_residual(x_, f_, stop);
  double fnorm = f_.template lpNorm<Eigen::Infinity>();
  // Modified Newton: iterations the current J has served (0: none yet), and whether to renew it.
  int jacobian_age = 0;
  bool renew = true;

  while (!status) {
    if (system_.budget_spent()) {
      // −∇φ at the last Jacobian: what a bound may hold (the window needs one to expire).
      if (box.active() && system_.jacobians() > 0) dx_ = -gradient_;
      status = system_.spent_status(summary.message, x_, dx_, fnorm);
      break;
    }
    const bool fresh = renew || jacobian_age >= newton_.jacobian_reuse;
    if ((status = sparse ? sparse_step(summary.message, fresh)
                         : dense_step(summary.message, monitor.iterations(), fresh))) {
      // A Krylov solve that fails on a stale J is tried again on a fresh one.
      if (!fresh && *status == Status::kSolverFailure) {
        status.reset();
        summary.message.clear();
        renew = true;
        continue;
      }
      break;
    }
    jacobian_age = fresh ? 1 : jacobian_age + 1;
    renew = false;
    if (box.active() || inexact) merit_gradient(sparse);

    // The Newton step (backtracked with a line search); in a box, when that finds no decrease,
    // the projected steepest-descent path from the Cauchy point of the linear model.
    bool descent_step = false;
    // A stale J's step gets a few backtracks (and without a line search must lower ‖F‖₂): when
    // it fails, J is renewed at x_ at once, before any fallback that would judge by it.
    bool accepted = search(dx_, 1.0, fresh ? line_search : stale_line_search);
    if (accepted && !fresh && !newton_.line_search && !(ft_.squaredNorm() < f_.squaredNorm())) {
      accepted = false;
    }
    if (!accepted && !fresh && !system_.budget_spent()) {
      renew = true;
      continue;
    }
    if (!accepted && newton_.line_search && box.active() && !system_.budget_spent()) {
      const double curvature = merit_curvature(sparse);
      if (curvature > 0.0) {
        dx_ = -gradient_;
        accepted = search(dx_, gradient_.squaredNorm() / curvature, line_search);
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
    if (inexact) {
      // η_{k+1} from the step taken (backtracked, projected or not), [EW96] choice 1; a descent
      // step was no Newton step: start afresh.
      if constexpr (N == Dynamic) {
        linear_residual_ = f_;
        linear_residual_.noalias() += sparse_jac_ * (xt_ - x_);
        if (descent_step) {
          forcing_.restart();
        } else {
          forcing_.update(ft_.norm(), f_.norm(), linear_residual_.norm());
        }
      }
    }
    // A J that no longer halves ‖F‖₂ is renewed (KINSOL renews on its own residual tests too).
    if (newton_.jacobian_reuse > 1 && ft_.squaredNorm() > 0.25 * f_.squaredNorm()) renew = true;
    x_ = xt_;
    f_ = ft_;
    fnorm = f_.template lpNorm<Eigen::Infinity>();
    // A step the box cut short, or a descent step, says nothing about the distance to a root.
    // A stale J's step is no Newton step: its size says nothing of the distance to a root.
    status = monitor.update(step, fnorm, x_.template lpNorm<Eigen::Infinity>(),
                            !projected && !descent_step && fresh);
    this->after_iteration(summary, status, monitor.iterations(), step, fnorm, x_);
  }

  x = x_;
  system_.finish(summary, *status, monitor, x, f_, stop);
  if (sparse) linear_.report(summary);
  return summary;
}

// Compiled once in the library for its sizes (nlobs/solvers/library_sizes.hpp).
#define NLOBS_EXTERN_NEWTON_ENGINE(n) extern template class NewtonEngine<n>;
NLOBS_FOR_EACH_LIBRARY_SIZE(NLOBS_EXTERN_NEWTON_ENGINE)
#undef NLOBS_EXTERN_NEWTON_ENGINE

}  // namespace nlobs
