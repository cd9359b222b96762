// One window-estimator step on the paper's modified-Chua window (T = 0.05 s, N = 3), noise-free
// and with σ = 0.01: what a chosen Ψ costs per sample. Ψ = I is the paper's map; newton (the chord
// map, Ψ = (∂H/∂w)⁻¹ refreshed only when a solve stops contracting) trades one Jacobian now and
// then for fewer iterations. Counters: iterations per step.
#include <benchmark/benchmark.h>

#include "nlobs/models/modified_chua.hpp"
#include "nlobs/observers/core/simulation.hpp"
#include "nlobs/observers/window/window_estimator.hpp"
#include "nlobs/solvers/engine_registry.hpp"

namespace {

using Chua = nlobs::Discretized<nlobs::ModifiedChua>;

nlobs::Measurements simulate_chua(double noise) {
  nlobs::SimulationOptions o;
  o.steps = 400;
  o.sample_time = 0.05;
  o.noise_std = noise;
  return nlobs::simulate(nlobs::paper_modified_chua(), Eigen::Vector3d(1.0, 2.1428, -0.1648), o);
}

const nlobs::Measurements& chua_data(bool noisy) {
  static const nlobs::Measurements clean = simulate_chua(0.0), noise = simulate_chua(0.01);
  return noisy ? noise : clean;
}

// state.range(0): 0 = identity, 1 = newton; range(1): 1 = σ = 0.01. The engine is the
// benchmark's name argument.
void window_step(benchmark::State& state, const char* engine) {
  const nlobs::Measurements& data = chua_data(state.range(1) == 1);
  nlobs::SolverOptions solver;
  solver.stop.step_tolerance = 1e-8;
  solver.stop.residual_tolerance = 1e-8;
  nlobs::WindowEstimatorOptions options;
  options.initial_estimate = Eigen::Vector3d(5.0, 10.0, -5.0);
  options.gain = state.range(0) == 0 ? nlobs::WindowGain::kIdentity : nlobs::WindowGain::kNewton;
  nlobs::WindowEstimator<Chua> estimator(nlobs::paper_modified_chua(), options,
                                         nlobs::EngineRegistry<3>::global().create(engine, solver));
  const Eigen::VectorXd no_input(0);
  // Past the first windows: the steady state of a run.
  for (long k = 0; k < 50; ++k) estimator.step(k, data.t[k], data.y.col(k), no_input);
  long k = 50, iterations = 0, solves = 0;
  for (auto _ : state) {
    const nlobs::ObserverStep& s = estimator.step(k, data.t[k], data.y.col(k), no_input);
    benchmark::DoNotOptimize(s.estimate.data());
    if (s.summary) iterations += s.summary->iterations, ++solves;
    if (++k == data.steps()) {
      state.PauseTiming();
      estimator.reset();
      for (k = 0; k < 50; ++k) estimator.step(k, data.t[k], data.y.col(k), no_input);
      state.ResumeTiming();
    }
  }
  state.counters["iterations"] =
      solves > 0 ? static_cast<double>(iterations) / static_cast<double>(solves) : 0.0;
}

BENCHMARK_CAPTURE(window_step, picard, "picard")
    ->ArgNames({"newton_psi", "noisy"})
    ->ArgsProduct({{0, 1}, {0, 1}});
BENCHMARK_CAPTURE(window_step, steffensen, "steffensen")
    ->ArgNames({"newton_psi", "noisy"})
    ->ArgsProduct({{0, 1}, {0, 1}});
BENCHMARK_CAPTURE(window_step, newton, "newton")
    ->ArgNames({"newton_psi", "noisy"})
    ->ArgsProduct({{0}, {0, 1}});

}  // namespace
