#pragma once
// Scenarios: a model, a true initial state, the data's length, noise and input, and the observers
// to run on it — built-in ones by name, or JSON files with the same fields (docs/cli.md,
// "Scenario files"). Parsing is strict: an unknown key, a wrong type or a missing field is an
// error naming the file and the key. The run layer's first part: a scenario is parsed (its
// model built once, here) and then run by run_scenario (scenario_run.hpp); `nlobs run` and the
// bindings call both.
#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "nlobs/observers/core/any_model.hpp"
#include "nlobs/observers/core/observer.hpp"
#include "nlobs/observers/core/simulation.hpp"
#include "nlobs/registry/model_registry.hpp"
#include "nlobs/registry/observer_types.hpp"
#include "nlobs/runs/input_schedule.hpp"

namespace nlobs {

// Samples of a run, checked before anything is allocated (n × steps doubles per observer are
// kept).
inline constexpr long kMaxScenarioSteps = 10'000'000;

// u(t) of the simulated plant, sampled at t_k and held over the sample. zero, constant and sin
// set every input alike; a schedule (piecewise_constant: steps, piecewise_linear: ramps) gives
// each input its own values at knots, from the scenario file or from a CSV file of t, u1..um.
struct InputSpec {
  // zero | constant | sin | piecewise_constant | piecewise_linear | file
  std::string kind = "zero";
  double value = 0.0;                       // constant
  double amplitude = 1.0, frequency = 1.0;  // sin: amplitude · sin(frequency · t)
  InputSchedule schedule{};                 // piecewise_constant, piecewise_linear, file
  std::string file{};  // file: the path it was read from, absolute (as given if that is no UTF-8)
};

// Figures a paper reported, printed beside ours: observer name → {"mse": x,
// "first_window_iterations": n}.
using ReportedFigures = std::map<std::string, std::map<std::string, double>>;

struct Scenario {
  std::string name;
  std::string description;  // where the scenario comes from (a paper's example), optional
  nlohmann::json model;     // {"name", "parameters": {...}, "scheme", "step", "substeps"}
  Eigen::VectorXd x0, initial_guess;
  long steps = 400;
  double noise = 0.0;
  double process_noise = 0.0;  // σ_w added to every state of the truth at every step
  std::uint64_t seed = 1;
  InputSpec input;
  std::vector<ObserverSpec> observers;
  ReportedFigures reported;
  // Start of "after": metrics after the transient (MSE, max error) count t >= settle_time;
  // negative: after the longest window has filled.
  double settle_time = -1.0;
  // The model parse_scenario built from `model` (to validate it), kept so that a run does not
  // build it again; scenario_model() builds afresh when `model` has changed since.
  struct BuiltModel {
    nlohmann::json spec;  // the `model` it was built from
    ModelInstance instance;
  };
  std::shared_ptr<const BuiltModel> built_model{};
};

// The built-in scenarios' names: runs/scenarios/NAME.json, compiled in (and installed to
// share/nlobs/scenarios/), read by the reader a user's file goes through.
std::vector<std::string> builtin_scenarios();
// A built-in name, or a path to a JSON file. Throws std::invalid_argument otherwise.
Scenario load_scenario(const std::string& name_or_file);
// `base_directory`: where a relative path in the scenario (an input file) is resolved; empty:
// the working directory. load_scenario passes the scenario file's own directory.
Scenario parse_scenario(const nlohmann::json& json, const std::string& where,
                        const std::string& base_directory = "");
nlohmann::json to_json(const Scenario& scenario);

// The scenario's model: the one parse_scenario built (shared by every copy of the Scenario and
// every run of it: a model with mutable state of its own is not to be run from two threads at
// once), or built afresh when `model` was edited since.
ModelInstance scenario_model(const Scenario& scenario);
// The true system simulated (steps, noise, seed, input); a domain exit ends the data early with
// Measurements::stop_message set.
Measurements simulate_scenario(const Scenario& scenario, const AnyModel& model);
// The observers a scenario describes, on its model. `trace_first_window`: window estimators
// record the engine's trace of their first window (for the convergence plot). `output_noise`:
// ObserverBuild's: the scenario's noise when the run simulates its data without process noise,
// else 0.
std::vector<std::unique_ptr<Observer>> make_observers(const Scenario& scenario,
                                                      const ModelInstance& model,
                                                      bool trace_first_window,
                                                      double output_noise = 0.0);
Eigen::VectorXd scenario_input(const Scenario& scenario, const AnyModel& model, long k);

// What the scenario's observer types report before a run (their entries' `report`: per PI
// channel the gains, N, the paper's δ and our ultimate bounds); warnings are appended.
nlohmann::json observer_reports(const Scenario& scenario, std::vector<std::string>* warnings);

}  // namespace nlobs
