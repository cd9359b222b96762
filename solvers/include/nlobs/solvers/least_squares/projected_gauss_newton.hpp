#pragma once
// Projected Gauss–Newton for a box-constrained nonlinear least-squares problem
//   min V(z) = ‖r(z)‖²_W   subject to  l ≤ z ≤ u,
// on a problem that brings its own linear algebra: the MHE's horizon, whose H is block
// tridiagonal ([RRM03]; observers/mhe/). At each iterate, with H = JᵀWJ and g = ∇(V/2) = JᵀWr,
// the states at a bound whose gradient points out of the box are held — their rows and columns
// of H become the identity's, their g 0 — and the step solved for the others (the projected
// Newton method of [Ber82]); d = −H⁻¹g is searched along z_α = Π(z + α d) by LineSearch
// (Armijo on V, δV = 2gᵀ(z_α − z), a path that does not descend given up at once), and when that
// path finds no decrease, along the scaled projected gradient d = −g ⊘ diag(H).
//
// Stop rules:
//   non_finite         V not finite at the start (the problem is left as it was)
//   singular_jacobian  H not positive definite (by rounding only when W is definite)
//   converged          before the search, the full projected step is small,
//                      ‖Π(z + d) − z‖∞ ≤ step_tolerance (1 + ‖z‖∞), or its first-order decrease is
//                      at V's rounding, −2gᵀ(Π(z + d) − z) ≤ cost_tolerance · V (where a line
//                      search would fail for want of digits); after it, the step taken meets the
//                      same bound (‖z‖∞ before the step)
//   stagnated          no decrease of V along either path
//   max_iterations     StopMonitor's, after max_iterations linearisations
// The Summary: iterations and jacobian_evaluations count the linearisations, function_evaluations
// the evaluations of V, residual_norm is ‖g‖∞ projected at the last linearisation, objective V at
// the answer, which is the lowest V found: a run cut short still lowered V from the start.
//
// The problem (a concept; its workspace and its counts are its own):
//   double start_cost()        V at the current z (+inf where not defined)
//   double linearise()         H and g at z with the active bounds held; returns ‖g‖∞ projected
//   bool newton_direction()    d = −H⁻¹g; false when H is not positive definite
//   void gradient_direction()  d = −g ⊘ diag(H)
//   std::pair<double, double> project(double α)   z_α = Π(z + α d) as the trial point; returns
//                              gᵀ(z_α − z) and ‖z_α − z‖∞
//   double trial_cost()        V at the trial point (+inf where not defined)
//   void accept()              z ← the trial point
//   double norm() const        ‖z‖∞
#include <algorithm>
#include <cmath>
#include <concepts>
#include <limits>
#include <optional>
#include <tuple>
#include <utility>

#include "nlobs/solvers/line_search.hpp"
#include "nlobs/solvers/stop_monitor.hpp"
#include "nlobs/solvers/summary.hpp"

namespace nlobs {

template <typename P>
concept ProjectedGaussNewtonProblem = requires(P& p, const P& cp, double alpha) {
  { p.start_cost() } -> std::convertible_to<double>;
  { p.linearise() } -> std::convertible_to<double>;
  { p.newton_direction() } -> std::convertible_to<bool>;
  p.gradient_direction();
  { p.project(alpha) } -> std::same_as<std::pair<double, double>>;
  { p.trial_cost() } -> std::convertible_to<double>;
  p.accept();
  { cp.norm() } -> std::convertible_to<double>;
};

struct ProjectedGaussNewtonOptions {
  long max_iterations = 100;      // linearisations, ≥ 1
  double step_tolerance = 1e-10;  // > 0, relative: ‖Δz‖∞ ≤ step_tolerance (1 + ‖z‖∞)
  double cost_tolerance = 1e-12;  // > 0, of V
  // Armijo on V (σ = 1e-4, α halved up to 30 times); require_descent is what the stop rules
  // above assume.
  LineSearch line_search{
      .sufficient_decrease = 1e-4, .shrink = 0.5, .max_backtracks = 30, .require_descent = true};

  // Throws InvalidInput naming the field (options_validation.hpp).
  void validate() const;
};

class ProjectedGaussNewton {
 public:
  static constexpr const char* kName = "gauss-newton";

  explicit ProjectedGaussNewton(ProjectedGaussNewtonOptions options = {})
      : options_(std::move(options)) {
    options_.validate();
    criteria_.max_iterations =
        static_cast<int>(std::min<long>(options_.max_iterations, std::numeric_limits<int>::max()));
    // The step tests are this solver's own (above): the monitor counts the iterations.
    criteria_.step_tolerance.reset();
    // V falls at every accepted step (Armijo): the tests for runs that do not are moot here.
    criteria_.stagnation_patience = 0;
    criteria_.residual_window = 0;
    criteria_.divergence_limit = std::numeric_limits<double>::infinity();
  }

  const ProjectedGaussNewtonOptions& options() const { return options_; }

  // Minimises V from the problem's current z, leaving z at the answer.
  template <ProjectedGaussNewtonProblem Problem>
  Summary minimise(Problem& problem) const;

 private:
  ProjectedGaussNewtonOptions options_;
  StopCriteria criteria_;
};

template <ProjectedGaussNewtonProblem Problem>
Summary ProjectedGaussNewton::minimise(Problem& problem) const {
  // The path z_α for LineSearch, m = V.
  struct Path {
    Problem& problem;
    double half_slope = 0.0, step = 0.0;
    int evaluations = 0;
    bool exhausted() const { return false; }
    bool move(double alpha) {
      std::tie(half_slope, step) = problem.project(alpha);
      return false;  // a path the box holds has δV = 0: require_descent ends it
    }
    double slope() const { return 2.0 * half_slope; }
    double merit() {
      ++evaluations;
      return problem.trial_cost();
    }
  };
  Path path{problem};
  // Along the current direction: true (z_α the trial point, V and the step's norm updated) when
  // a point decreases V enough.
  const auto search = [&](double& value, double& step) {
    const LineSearch::Result result = options_.line_search.search(path, 1.0, value);
    if (!result.accepted()) return false;
    value = result.merit;
    step = path.step;
    return true;
  };

  Summary summary;
  summary.engine = kName;
  double value = problem.start_cost();
  path.evaluations = 1;
  int linearisations = 0;
  if (!std::isfinite(value)) {
    summary.status = Status::kNonFinite;
    summary.message = "the cost V is not finite at the start";
  } else {
    StopMonitor monitor(criteria_, problem.norm(), /*estimate_lipschitz=*/false);
    std::optional<Status> status;
    while (!status) {
      summary.residual_norm = problem.linearise();
      ++linearisations;
      if (!problem.newton_direction()) {
        status = Status::kSingularJacobian;
        summary.message = "the Gauss-Newton matrix is not positive definite";
        break;
      }
      const double norm = problem.norm();
      const auto [slope, full_step] = problem.project(1.0);
      // A projected step that does not descend (slope ≥ 0) is not a converged one: the line
      // search refuses it and the projected gradient is tried.
      if (full_step <= options_.step_tolerance * (1.0 + norm) ||
          (slope < 0.0 && -2.0 * slope <= options_.cost_tolerance * value)) {
        status = Status::kConverged;
        summary.step_norm = full_step;
        break;
      }
      double step = 0.0;
      bool moved = search(value, step);
      if (!moved) {
        problem.gradient_direction();
        moved = search(value, step);
      }
      if (!moved) {
        status = Status::kStagnated;
        summary.message = "no decrease of the cost along the projected Newton or gradient path";
        break;
      }
      problem.accept();
      summary.step_norm = step;
      if (step <= options_.step_tolerance * (1.0 + norm)) {
        status = Status::kConverged;
      } else {
        // (‖g‖ is no residual that falls to 0 at a least-squares minimum: unknown to the
        // monitor.)
        status = monitor.update(step, std::numeric_limits<double>::quiet_NaN(), norm);
      }
    }
    summary.status = *status;
  }
  summary.iterations = linearisations;
  summary.jacobian_evaluations = linearisations;
  summary.function_evaluations = path.evaluations;
  summary.objective = value;
  return summary;
}

}  // namespace nlobs
