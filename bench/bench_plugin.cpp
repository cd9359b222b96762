// Code from a plugin against the same code built into the program (issue: a plugin's model or
// engine runs as fast as a built-in, within 5 %). The example plugin (examples/plugin) is loaded
// at the first benchmark; its sources are also compiled into this binary:
//   engine/*: Broyden's second method (bad-broyden) on the plugin's bratu-1d (n = 8) from u = 0,
//   through the registry (the
//             plugin's copy) or constructed here; the problem is the same object.
//   model/*:  one window-estimator step (engine newton, N = the default window) on the
//             FitzHugh–Nagumo model registered by the plugin, or by this binary under another
//             name; the CLI's path: model registry → observer type "window".
#include <benchmark/benchmark.h>

#include <nlohmann/json.hpp>

#include "bad_broyden_engine.hpp"
#include "fitzhugh_nagumo.hpp"
#include "nlobs/observers/core/simulation.hpp"
#include "nlobs/registry/observer_types.hpp"
#include "nlobs/registry/plugin.hpp"
#include "nlobs/registry/register_model.hpp"

namespace {

void load_example_plugin() {
  static const bool loaded = [] {
    nlobs::load_plugin(NLOBS_EXAMPLE_PLUGIN);
    nlobs::model_registry().add(
        nlobs::model_entry(nlobs::ModelDefinition<example::FitzHughNagumo>{
            .name = "fitzhugh-nagumo-built-in",
            .description = "the example plugin's model, compiled into the benchmark",
            .default_step = 0.05}),
        "nlobs_bench");
    return true;
  }();
  (void)loaded;
}

const nlobs::TestProblem& bratu() {
  load_example_plugin();
  static const nlobs::TestProblem problem = [] {
    auto selection = nlobs::select_problems("example/bratu-1d", nlobs::problem_set_registry());
    return selection.problems.at(0);
  }();
  return problem;
}

nlobs::SolverOptions tight() {
  nlobs::SolverOptions o;
  o.stop.step_tolerance = 1e-10;
  o.stop.residual_tolerance = 1e-10;
  return o;
}

void solve_bratu(benchmark::State& state, nlobs::Engine<>& engine) {
  const nlobs::TestProblem& p = bratu();
  nlobs::Vector<nlobs::Dynamic> x;
  long evaluations = 0, solves = 0;
  for (auto _ : state) {
    x = p.starts.at(0).x;
    const nlobs::Summary s = engine.solve_least_squares(p.residual, x);
    benchmark::DoNotOptimize(x.data());
    if (!s.converged()) state.SkipWithError("bad-broyden did not converge on bratu-1d");
    evaluations += s.function_evaluations, ++solves;
  }
  state.counters["evaluations"] = static_cast<double>(evaluations) / static_cast<double>(solves);
}

void BM_PluginEngine(benchmark::State& state) {
  load_example_plugin();
  auto engine = nlobs::EngineRegistry<nlobs::Dynamic>::global().create("bad-broyden", tight());
  solve_bratu(state, *engine);
}
BENCHMARK(BM_PluginEngine)->Name("plugin/engine/bad_broyden_bratu8/plugin");

void BM_BuiltInEngine(benchmark::State& state) {
  example::BadBroydenEngine<> engine({}, tight());
  solve_bratu(state, engine);
}
BENCHMARK(BM_BuiltInEngine)->Name("plugin/engine/bad_broyden_bratu8/built_in");

// One window step on the model `name` from the registry, the CLI's way.
void window_step(benchmark::State& state, const char* name) {
  load_example_plugin();
  const nlohmann::json model_spec = {{"name", name}};
  nlobs::JsonReader model_reader(model_spec, "bench model");
  const nlobs::ModelInstance model = nlobs::make_model_instance(model_reader);
  nlobs::SimulationOptions o;
  o.steps = 400;
  o.sample_time = 0.05;
  const nlobs::Measurements data = nlobs::simulate(model.discrete, Eigen::Vector2d(1.0, 0.5), o);
  const nlohmann::json observer_spec = {{"type", "window"}, {"engine", "newton"}};
  nlobs::JsonReader observer_reader(observer_spec, "bench observer");
  const nlobs::ObserverSpec spec = nlobs::parse_observer_spec(observer_reader, model);
  auto observer = nlobs::build_observer(spec, model, Eigen::Vector2d(0.0, 0.0), "bench", false);
  const Eigen::VectorXd no_input(0);
  for (long k = 0; k < 50; ++k) observer->step(k, data.t[k], data.y.col(k), no_input);
  long k = 50;
  for (auto _ : state) {
    const nlobs::ObserverStep& s = observer->step(k, data.t[k], data.y.col(k), no_input);
    benchmark::DoNotOptimize(s.estimate.data());
    if (++k == data.steps()) {
      state.PauseTiming();
      observer->reset();
      for (k = 0; k < 50; ++k) observer->step(k, data.t[k], data.y.col(k), no_input);
      state.ResumeTiming();
    }
  }
}
BENCHMARK_CAPTURE(window_step, plugin, "fitzhugh-nagumo")
    ->Name("plugin/model/fitzhugh_nagumo_window/plugin");
BENCHMARK_CAPTURE(window_step, built_in, "fitzhugh-nagumo-built-in")
    ->Name("plugin/model/fitzhugh_nagumo_window/built_in");

}  // namespace
