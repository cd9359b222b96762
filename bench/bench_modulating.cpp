// The modulating-function observer ([MF-LTV]): µs per sample over a recorded run of the LTI
// example (δ = 10 ms) as the horizon grows (the FIR is n(n+1) dot products of T/δ + 1 taps),
// in FIR mode and in sampled-data mode (outputs every 0.1 s, the predictor between); and the
// offline kernel design (minimal and noise-optimal degree). Counter: eta_error = ‖η − η̂‖ at
// the last sample.
#include <benchmark/benchmark.h>

#include "nlobs/models/discretization.hpp"
#include "nlobs/models/systems.hpp"
#include "nlobs/observers/core/simulation.hpp"
#include "nlobs/observers/modulating/modulating_function_observer.hpp"

namespace {

using namespace nlobs;

const Measurements& lti_data() {
  static const Measurements data = [] {
    SimulationOptions o;
    o.steps = 2001;
    o.sample_time = 0.01;
    return simulate(Discretized<LtiOutputInjection>(LtiOutputInjection{}, 0.01, Scheme::kRk4),
                    Eigen::Vector2d(2.0, 0.0), o);
  }();
  return data;
}

void BM_ModulatingStep(benchmark::State& state) {
  const Measurements& data = lti_data();
  ModulatingOptions o;
  o.initial_estimate = Eigen::Vector2d::Zero();
  o.sample_time = 0.01;
  o.horizon = 0.01 * static_cast<double>(state.range(0));
  o.sample_period = state.range(1) ? 0.1 : 0.0;
  double error = 0.0;
  for (auto _ : state) {
    state.PauseTiming();
    ModulatingFunctionObserver<LtiInjectionForm> observer(LtiInjectionForm{}, o);
    state.ResumeTiming();
    for (Eigen::Index k = 0; k < data.steps(); ++k) {
      observer.step(k, data.t[k], data.y.col(k), data.u.col(k));
    }
    const Eigen::Index K = data.steps() - 1;
    error = (observer.coordinates_at(data.x.col(K), data.t[K]) - Eigen::VectorXd(observer.eta()))
                .norm();
  }
  state.SetItemsProcessed(state.iterations() * data.steps());
  state.counters["us_per_step"] = benchmark::Counter(
      static_cast<double>(data.steps()) * 1e-6 * static_cast<double>(state.iterations()),
      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["eta_error"] = error;
}
BENCHMARK(BM_ModulatingStep)
    ->ArgNames({"taps", "sampled"})
    ->ArgsProduct({{20, 100, 400}, {0, 1}})
    ->Unit(benchmark::kMillisecond);

void BM_ModulatingKernelDesign(benchmark::State& state) {
  ModulatingKernelOptions o;
  o.degree = static_cast<int>(state.range(0));
  o.noise_weights = Eigen::Vector2d(1.0, 0.5);
  for (auto _ : state) {
    const ModulatingKernels K(2, 1.0, o);
    benchmark::DoNotOptimize(K.value(0, 2, 0.5));
  }
}
BENCHMARK(BM_ModulatingKernelDesign)->Arg(3)->Arg(10)->Unit(benchmark::kMicrosecond);

}  // namespace
