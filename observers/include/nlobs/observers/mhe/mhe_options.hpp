#pragma once
// The options of MheEstimator (mhe_estimator.hpp), apart from the template so that the registry
// and the CLI parse and validate them without instantiating it.
#include <Eigen/Core>
#include <string>

namespace nlobs {

struct MheOptions {
  std::string name = "mhe";                  // in reports
  Eigen::VectorXd initial_estimate{};        // x̄_0, the prior mean of x_0: n finite numbers
  Eigen::MatrixXd initial_covariance{};      // P_0 (n × n), the prior's covariance; empty: I
  Eigen::MatrixXd process_covariance{};      // Q (n × n), of w_i; empty: 1e-6 I
  Eigen::MatrixXd measurement_covariance{};  // R (p × p), of v_i; empty: 1e-4 I
  // 1 ≤ N ≤ kMaxHorizon: the samples y_{k−N+1..k} the problem at k holds (the full-information
  // problem on the samples so far until k + 1 = N).
  long horizon = 10;
  // Every sample solves the whole horizon, O(N n³) per Gauss–Newton iteration (about 0.7 µs · N
  // for n = 3, docs/observers.md): N = 10⁴ is some 7 ms a sample, 10⁵ would make a run of 10⁵
  // samples last hours. Longer horizons are refused rather than left to run.
  static constexpr long kMaxHorizon = 10000;
  // Box on every state of the horizon, l ≤ x_i ≤ u: empty for no bound on that side, ±inf for
  // no bound on a component; the prior x̄_0 must lie inside.
  Eigen::VectorXd lower_bounds{}, upper_bounds{};
  // Gauss–Newton iterations per sample (≥ 1), each one linearisation of the window and one
  // block-tridiagonal solve with a projected backtracking line search.
  long max_iterations = 100;
  // One Gauss–Newton iteration per sample, warm-started by shifting ([DBS05]'s real-time
  // iteration): max_iterations is then 1 and a step is reported converged only if it met
  // step_tolerance or cost_tolerance (otherwise max_iterations, and used all the same).
  bool real_time_iteration = false;
  // Converged when the step is small: ‖Δz‖∞ ≤ step_tolerance · (1 + ‖z‖∞), z the window's
  // states; > 0.
  double step_tolerance = 1e-10;
  // Converged when the full step's first-order decrease of V is at most cost_tolerance · V: at
  // the rounding floor of V (where a line search fails for want of digits), > 0.
  double cost_tolerance = 1e-12;
  // Throws InvalidInput naming the field: an empty name; an initial estimate empty or not
  // finite; a covariance given but not square, finite, symmetric and positive definite (the
  // cost weighs by its inverse); horizon or max_iterations < 1, horizon > kMaxHorizon;
  // step_tolerance or cost_tolerance ≤ 0; bounds with NaN, lower > upper, or sizes that differ; an
  // initial estimate outside the bounds.
  void validate() const;
};

}  // namespace nlobs
