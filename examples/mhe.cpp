// Moving-horizon estimation on the batch reactor of the MHE literature: a poor prior, a total-
// pressure measurement, concentrations that must stay ≥ 0. The EKF and the MHE share the model
// and the noise statistics; the MHE adds the bounds. Every observer is X(model, XOptions) and
// one step(k, t, y, u) per sample.
#include <cstdio>
#include <nlobs/models/discretization.hpp>
#include <nlobs/models/systems.hpp>
#include <nlobs/observers/baselines/baselines.hpp>
#include <nlobs/observers/core/simulation.hpp>
#include <nlobs/observers/mhe/mhe_estimator.hpp>

int main() {
  using Reactor = nlobs::Discretized<nlobs::BatchReactor>;
  const Reactor model(nlobs::BatchReactor{}, 0.25, nlobs::Scheme::kRk4);  // Δ = 0.25

  nlobs::SimulationOptions sim;  // the truth: x0 = (0.5, 0.05, 0), σ_v = 0.25, σ_w = 0.001
  sim.steps = 121;
  sim.noise_std = 0.25;
  sim.process_noise_std = 0.001;
  const nlobs::Measurements data = nlobs::simulate(model, Eigen::Vector3d(0.5, 0.05, 0.0), sim);

  nlobs::MheOptions mhe_options;
  mhe_options.initial_estimate = Eigen::Vector3d(1.0, 0.0, 4.0);        // x̄_0, far from x0
  mhe_options.initial_covariance = 0.25 * Eigen::Matrix3d::Identity();  // σ_p = 0.5
  mhe_options.process_covariance = 1e-6 * Eigen::Matrix3d::Identity();  // σ_w²
  mhe_options.measurement_covariance = Eigen::MatrixXd::Constant(1, 1, 0.0625);  // σ_v²
  mhe_options.horizon = 10;
  mhe_options.lower_bounds = Eigen::Vector3d::Zero();  // c ≥ 0
  nlobs::MheEstimator<Reactor> mhe(model, mhe_options);

  nlobs::EkfOptions ekf_options;
  ekf_options.initial_estimate = mhe_options.initial_estimate;
  ekf_options.initial_covariance = mhe_options.initial_covariance;
  ekf_options.process_covariance = mhe_options.process_covariance;
  ekf_options.measurement_covariance = mhe_options.measurement_covariance;
  nlobs::ExtendedKalmanFilter<Reactor> ekf(model, ekf_options);

  Eigen::Vector3d mhe_estimate = Eigen::Vector3d::Zero(), ekf_estimate = mhe_estimate;
  for (long k = 0; k < data.steps(); ++k) {
    const Eigen::VectorXd y = data.y.col(k), u = data.u.col(k);
    const nlobs::ObserverStep& step = mhe.step(k, data.t[k], y, u);
    mhe_estimate = step.estimate;
    ekf_estimate = ekf.step(k, data.t[k], y, u).estimate;
    if (k % 40 == 0)
      std::printf("t = %4.1f  %s\n", data.t[k], step.summary->brief_report().c_str());
  }
  const Eigen::Vector3d truth = data.x.col(data.steps() - 1);
  std::printf("t = 30: true c = (%.3f, %.3f, %.3f)\n", truth[0], truth[1], truth[2]);
  std::printf("  bounded MHE    (%.3f, %.3f, %.3f)\n", mhe_estimate[0], mhe_estimate[1],
              mhe_estimate[2]);
  std::printf("  EKF            (%.3f, %.3f, %.3f)\n", ekf_estimate[0], ekf_estimate[1],
              ekf_estimate[2]);
  return (mhe_estimate - truth).norm() < 0.02 ? 0 : 1;
}
