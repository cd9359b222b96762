// The cost of one sample of each estimator as the model grows: the reaction–diffusion chain
// (nlobs/models/reaction_diffusion_chain.hpp, n cells, 8 point sensors, RK4 with h = 0.25) from
// a front at n/4, the estimators started from one at n/2. One iteration = one observer.step on
// the next sample (the plant's O(n) step to make it is inside and negligible). Variants:
//   EKF, the chain's own type: F traced and compressed (one AD pass), F P Fᵀ sparse;
//   EKF through AnyModel (the CLI's way): dense AD Jacobian (⌈n/8⌉ passes), sparse product;
//   EKF with sparse_jacobian = false: dense F and products (the O(n³) of before);
//   UKF (α = 2/√n): 2n + 1 sigma points, a Cholesky factor and the weighted sums, O(n³);
//   MHE, horizon 5, one real-time iteration: block-tridiagonal Gauss–Newton with dense
//     n × n blocks, O(N n³);
//   a least-squares window (levenberg-marquardt, N = n/4 samples of 8 outputs): dense J.
// docs/observers.md, "Observers at scale", has the figures.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "chain_estimation.hpp"
#include "nlobs/models/discretization.hpp"
#include "nlobs/models/reaction_diffusion_chain.hpp"
#include "nlobs/observers/baselines/baselines.hpp"
#include "nlobs/observers/baselines/unscented_kalman_filter.hpp"
#include "nlobs/observers/core/any_model.hpp"
#include "nlobs/observers/mhe/mhe_estimator.hpp"
#include "nlobs/observers/window/window_estimator.hpp"

namespace {

using nlobs::Discretized;
using nlobs::ReactionDiffusionChain;
using nlobs::test::chain_kalman_options;
using Sampled = Discretized<ReactionDiffusionChain>;
constexpr double kStep = 0.25;
constexpr long kSensors = 8;

Sampled chain(long n) {
  return Sampled(ReactionDiffusionChain({.cells = n, .sensors = kSensors}), kStep,
                 nlobs::Scheme::kRk4);
}

// Steps `observer` through the plant's samples, `warm` of them untimed first (the EKF traces its
// pattern there, a window fills).
void run(benchmark::State& state, const Sampled& model, nlobs::Observer& observer, int warm) {
  const double n = static_cast<double>(model.states());
  Eigen::VectorXd x = model.model().front(n / 4.0, 3.0);
  const Eigen::VectorXd u(0);
  long k = 0;
  double iterations = 0.0;  // of the solver, where a step solves a problem (window, MHE)
  const auto next = [&] {
    const nlobs::ObserverStep& s =
        observer.step(k, static_cast<double>(k) * kStep, Eigen::VectorXd(model.h(x)), u);
    x = model.f(x, u, k);
    ++k;
    if (s.summary) iterations += s.summary->iterations;
    return s.failure.empty();
  };
  for (int i = 0; i < warm; ++i) next();
  iterations = 0.0;
  for (auto _ : state) {
    if (!next()) {
      state.SkipWithError("the observer reported a failure");
      return;
    }
  }
  state.counters["n"] = n;
  state.counters["iterations"] = benchmark::Counter(iterations, benchmark::Counter::kAvgIterations);
}

Eigen::VectorXd start_of(const Sampled& model) {
  return model.model().front(static_cast<double>(model.states()) / 2.0, 3.0);
}

void BM_EkfStepChain(benchmark::State& state) {
  const Sampled model = chain(state.range(0));
  auto o = chain_kalman_options<nlobs::EkfOptions>(start_of(model));
  o.sparse_jacobian = state.range(1) != 0;
  nlobs::ExtendedKalmanFilter<Sampled> ekf(model, o);
  run(state, model, ekf, 2);
}
BENCHMARK(BM_EkfStepChain)
    ->ArgNames({"n", "sparse"})
    ->Args({100, 1})
    ->Args({200, 1})
    ->Args({400, 1})
    ->Args({800, 1})
    ->Args({1600, 1})
    ->Args({3200, 1})
    ->Args({100, 0})
    ->Args({200, 0})
    ->Args({400, 0})
    ->Args({800, 0})
    ->Args({1600, 0})
    ->Unit(benchmark::kMillisecond);

void BM_EkfStepChainAnyModel(benchmark::State& state) {
  const Sampled model = chain(state.range(0));
  nlobs::ExtendedKalmanFilter<nlobs::AnyModel> ekf(
      nlobs::AnyModel("chain", model, kStep),
      chain_kalman_options<nlobs::EkfOptions>(start_of(model)));
  run(state, model, ekf, 2);
}
BENCHMARK(BM_EkfStepChainAnyModel)
    ->RangeMultiplier(2)
    ->Range(100, 3200)
    ->Unit(benchmark::kMillisecond);

void BM_UkfStepChain(benchmark::State& state) {
  const Sampled model = chain(state.range(0));
  auto o = chain_kalman_options<nlobs::UkfOptions>(start_of(model));
  // The sigma points lie α √n σ from x̂: α = 2 / √n keeps them one unit away (σ = 0.5), where
  // the RK4 step stays stable; a fixed α = 0.3 fails from n = 256 on (they blow up).
  o.alpha = std::min(1.0, 2.0 / std::sqrt(static_cast<double>(state.range(0))));
  nlobs::UnscentedKalmanFilter<Sampled> ukf(model, o);
  run(state, model, ukf, 2);
}
BENCHMARK(BM_UkfStepChain)->RangeMultiplier(2)->Range(50, 800)->Unit(benchmark::kMillisecond);

void BM_MheStepChain(benchmark::State& state) {
  const Sampled model = chain(state.range(0));
  auto o = chain_kalman_options<nlobs::MheOptions>(start_of(model));
  o.horizon = 5;
  o.real_time_iteration = true;
  nlobs::MheEstimator<Sampled> mhe(model, o);
  run(state, model, mhe, 6);
}
BENCHMARK(BM_MheStepChain)->RangeMultiplier(2)->Range(25, 400)->Unit(benchmark::kMillisecond);

void BM_WindowStepChain(benchmark::State& state) {
  const Sampled model = chain(state.range(0));
  nlobs::WindowEstimatorOptions o;
  o.initial_estimate = start_of(model);
  o.window = 2 * state.range(0) / kSensors;  // twice as many outputs as states
  auto window = nlobs::make_window_estimator(model, "levenberg-marquardt", o);
  run(state, model, *window, static_cast<int>(o.window) + 1);
}
BENCHMARK(BM_WindowStepChain)->RangeMultiplier(2)->Range(16, 64)->Unit(benchmark::kMillisecond);

}  // namespace
