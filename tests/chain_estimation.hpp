#pragma once
// The reaction–diffusion chain's estimation setting that tests/test_observers_at_scale.cpp and
// bench/bench_observers_at_scale.cpp share: the statistics every Kalman-type estimator starts
// from there.
#include <Eigen/Core>

namespace nlobs::test {

// x̂_0 = start, P0 = 0.25 I (fronts are within a unit), Q = 1e-6 I, R the default 1e-4 I:
// EkfOptions, UkfOptions or MheOptions.
template <typename Options>
Options chain_kalman_options(const Eigen::VectorXd& start) {
  Options o;
  o.initial_estimate = start;
  const Eigen::Index n = start.size();
  o.initial_covariance = 0.25 * Eigen::MatrixXd::Identity(n, n);
  o.process_covariance = 1e-6 * Eigen::MatrixXd::Identity(n, n);
  return o;
}

}  // namespace nlobs::test
