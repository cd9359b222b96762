#pragma once
// One summary format for every engine (compare Ceres' Solver::Summary).
#include <Eigen/Core>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "nlobs/solvers/engine_name.hpp"
#include "nlobs/solvers/status.hpp"
#include "nlobs/solvers/stop_criteria.hpp"

namespace nlobs {

// One completed iteration, recorded when SolverOptions::record_trace is set.
struct TraceEntry {
  int iteration = 0;
  double step_norm = 0.0;      // ‖x_l − x_{l−1}‖∞
  double residual_norm = 0.0;  // ‖G(x) − x‖∞ at the last point G was evaluated
  Eigen::VectorXd x;           // the iterate x_l
};

struct Summary {
  Status status = Status::kInvalidInput;
  EngineName engine;             // the engine's name(), held here (engine_name.hpp)
  int iterations = 0;            // completed iterations of the engine's sequence
  int function_evaluations = 0;  // evaluations of G (or F), including finite differences
  int jacobian_evaluations = 0;  // Jacobians computed (user-supplied, AD or finite differences)
  // The sparse path's linear solver (nlobs/solvers/linear/): its name, its setups
  // (factorisations or preconditioner builds) and Krylov iterations; empty and 0 on dense paths.
  std::string linear_solver;
  int linear_setups = 0;
  int linear_iterations = 0;
  double step_norm = 0.0;  // ‖x_l − x_{l−1}‖∞ of the last step
  double residual_norm = std::numeric_limits<double>::quiet_NaN();  // ‖G(x) − x‖∞ at the
                                                                    // returned x (NaN: unknown)
  // Ratio of the last consecutive step norms: estimates the linear convergence factor.
  std::optional<double> contraction_estimate;
  // The L used for the error bound: StopCriteria::lipschitz_constant or, if unset and the
  // steps contract, contraction_estimate (then lipschitz_is_estimate = true).
  std::optional<double> lipschitz_constant;
  bool lipschitz_is_estimate = false;
  // ‖x − p‖∞ ≤ residual_norm / (1 − L) ([MGFF23]): rigorous when L is a valid Lipschitz
  // constant of G on a convex set holding x and the fixed point p; an estimate otherwise.
  std::optional<double> error_bound;
  // A priori iteration count ⌈m / log10(1/L)⌉ (eq. 64), m = −log10 of the error (else step)
  // tolerance: what a contraction with factor L needs to gain m digits.
  std::optional<int> a_priori_iterations;
  // Minimisation engines (NLopt): the objective at the returned x.
  std::optional<double> objective;
  std::string message;  // detail for kInvalidInput, kSingularJacobian, kSolverFailure, backends
  // An engine that runs another library (the reference engines: KINSOL, MINPACK, GSL, PETSc):
  // that library's own account of the run, as nlobs names it ("xtol_too_small",
  // "kin_linesearch_nonconv", "diverged_line_search"), of which `status` is the nearest Status.
  // What `nlobs suite` shows as the row's status. Empty for nlobs' own engines.
  std::string library_status;
  // A polyalgorithm (auto): the label of the engine whose answer this is; empty otherwise.
  std::string stage;
  std::vector<TraceEntry> trace;

  // What usable() judges by, recorded by the engine (record_answer()) from the x it returned
  // and the StopCriteria it was given.
  bool answer_recorded = false;     // record_answer() was called (a user's engine may not)
  bool point_finite = false;        // every entry of the returned x is finite
  bool residual_minimised = false;  // least squares / minimisation: ‖F‖ need not reach 0
  std::optional<double> residual_tolerance;  // StopCriteria::residual_tolerance, if asked for
  double acceptance_tolerance = 1e-6;        // StopCriteria::acceptance_tolerance

  bool converged() const { return status == Status::kConverged; }
  // The one policy for "this answer may be used" (every observer follows it): the returned x
  // is finite and ‖F‖∞ is not infinite, and with small = max(residual_tolerance,
  // acceptance_tolerance):
  //   converged:  ‖F‖∞ ≤ small when a residual_tolerance was asked for (a step criterion met
  //               first under Combine::kAny does not excuse a residual above it);
  //   cut short (max_iterations, max_evaluations, stagnated, repeated_iterates,
  //               rounding_floor, local_minimum, stopped_by_callback): only with ‖F‖∞ ≤ small, on a
  //               root problem (at a least-squares or minimisation point ‖F‖ does not show a
  //               solution: not usable);
  //   diverged, non_finite, singular_jacobian, solver_failure, invalid_input,
  //   blocked_by_bound: never.
  bool usable() const;
  // Why usable() is false, in one line ("stagnated with |F| 1.500e+03 > acceptance_tolerance
  // 1.000e-06"); empty if usable.
  std::string unusable_reason() const;
  // Records the returned point and the criteria usable() needs; every engine calls it last
  // (a caller holding the answer of an engine that did not may call it for the engine).
  template <typename Vec>
  void record_answer(const Vec& x, const StopCriteria& criteria, bool minimised = false) {
    answer_recorded = true;
    point_finite = x.allFinite();
    residual_minimised = minimised;
    residual_tolerance = criteria.residual_tolerance;
    acceptance_tolerance = criteria.acceptance_tolerance;
  }
  // "steffensen: converged after 12 iterations (25 evaluations), |step| 3.1e-09, |F| 2.0e-12"
  std::string brief_report() const;
  // Multi-line report of every field.
  std::string full_report() const;
};

}  // namespace nlobs
