#pragma once
// One summary format for every engine (compare Ceres' Solver::Summary).
#include <Eigen/Core>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "nlobs/solvers/status.hpp"

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
  std::string_view engine;       // the engine's name(); valid while the engine lives
  int iterations = 0;            // completed iterations of the engine's sequence
  int function_evaluations = 0;  // evaluations of G (or F), including finite differences
  int jacobian_evaluations = 0;  // Jacobians computed (user-supplied, AD or finite differences)
  double step_norm = 0.0;        // ‖x_l − x_{l−1}‖∞ of the last step
  double residual_norm = 0.0;    // ‖G(x) − x‖∞ at the returned x
  // Ratio of the last consecutive step norms: estimates the linear convergence factor.
  std::optional<double> contraction_estimate;
  // The L used for the error bound: StopCriteria::lipschitz_constant or, if unset and the
  // steps contract, contraction_estimate (then lipschitz_is_estimate = true).
  std::optional<double> lipschitz_constant;
  bool lipschitz_is_estimate = false;
  // ‖x − p‖∞ ≤ residual_norm / (1 − L) (METHODS §1): rigorous when L is a valid Lipschitz
  // constant of G on a convex set holding x and the fixed point p; an estimate otherwise.
  std::optional<double> error_bound;
  // A priori iteration count ⌈m / log10(1/L)⌉ (eq. 64), m = −log10 of the error (else step)
  // tolerance: what a contraction with factor L needs to gain m digits.
  std::optional<int> a_priori_iterations;
  // Minimisation engines (NLopt): the objective at the returned x.
  std::optional<double> objective;
  std::string message;  // detail for kInvalidInput, kSingularJacobian, kSolverFailure, backends
  std::vector<TraceEntry> trace;

  bool converged() const { return status == Status::kConverged; }
  // "steffensen: converged after 12 iterations (25 evaluations), |step| 3.1e-09, |F| 2.0e-12"
  std::string brief_report() const;
  // Multi-line report of every field.
  std::string full_report() const;
};

}  // namespace nlobs
