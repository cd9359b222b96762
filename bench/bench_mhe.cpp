// One step of the Kalman-type estimators on the paper's modified-Chua model (n = 3, p = 1,
// T = 0.05 s, output noise σ = 0.01, the chua-fp statistics Q = 1e-6 I, R = 1e-4, P0 = 10 I):
// the EKF, the UKF and the MHE with N = 10 and 50, solved to convergence and with one real-time
// iteration. Timed past the first 60 samples (the horizon full). Counter: Gauss–Newton
// iterations per step.
#include <benchmark/benchmark.h>

#include <memory>

#include "nlobs/models/modified_chua.hpp"
#include "nlobs/observers/baselines/baselines.hpp"
#include "nlobs/observers/baselines/unscented_kalman_filter.hpp"
#include "nlobs/observers/core/simulation.hpp"
#include "nlobs/observers/mhe/mhe_estimator.hpp"

namespace {

using Chua = nlobs::Discretized<nlobs::ModifiedChua>;
constexpr long kWarmUp = 60;

const nlobs::Measurements& noisy_chua() {
  static const nlobs::Measurements data = [] {
    nlobs::SimulationOptions o;
    o.steps = 400;
    o.noise_std = 0.01;
    return nlobs::simulate(nlobs::paper_modified_chua(), Eigen::Vector3d(1.0, 2.1428, -0.1648), o);
  }();
  return data;
}

template <typename Options>
Options chua_statistics(Options o) {
  o.initial_estimate = Eigen::Vector3d(5.0, 10.0, -5.0);
  o.process_covariance = 1e-6 * Eigen::Matrix3d::Identity();
  o.measurement_covariance = Eigen::MatrixXd::Constant(1, 1, 1e-4);
  o.initial_covariance = 10.0 * Eigen::Matrix3d::Identity();
  return o;
}

void time_steps(benchmark::State& state, nlobs::Observer& observer) {
  const nlobs::Measurements& data = noisy_chua();
  const Eigen::VectorXd no_input(0);
  const auto warm_up = [&] {
    observer.reset();
    for (long k = 0; k < kWarmUp; ++k) observer.step(k, data.t[k], data.y.col(k), no_input);
  };
  warm_up();
  long k = kWarmUp, iterations = 0, steps = 0;
  for (auto _ : state) {
    const nlobs::ObserverStep& s = observer.step(k, data.t[k], data.y.col(k), no_input);
    benchmark::DoNotOptimize(s.estimate.data());
    if (s.summary) iterations += s.summary->iterations;
    ++steps;
    if (++k == data.steps()) {
      state.PauseTiming();
      warm_up();
      k = kWarmUp;
      state.ResumeTiming();
    }
  }
  state.counters["iterations"] = static_cast<double>(iterations) / static_cast<double>(steps);
}

void ekf_step(benchmark::State& state) {
  nlobs::ExtendedKalmanFilter<Chua> ekf(nlobs::paper_modified_chua(),
                                        chua_statistics(nlobs::EkfOptions{}));
  time_steps(state, ekf);
}

void ukf_step(benchmark::State& state) {
  nlobs::UnscentedKalmanFilter<Chua> ukf(nlobs::paper_modified_chua(),
                                         chua_statistics(nlobs::UkfOptions{}));
  time_steps(state, ukf);
}

// state.range(0): the horizon N; range(1): 1 = one real-time iteration per sample.
void mhe_step(benchmark::State& state) {
  nlobs::MheOptions o = chua_statistics(nlobs::MheOptions{});
  o.horizon = state.range(0);
  o.real_time_iteration = state.range(1) == 1;
  nlobs::MheEstimator<Chua> mhe(nlobs::paper_modified_chua(), o);
  time_steps(state, mhe);
}

BENCHMARK(ekf_step);
BENCHMARK(ukf_step);
BENCHMARK(mhe_step)->ArgNames({"N", "rti"})->ArgsProduct({{10, 50}, {0, 1}});

}  // namespace
