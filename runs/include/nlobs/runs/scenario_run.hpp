#pragma once
// A scenario run below any program: parse (scenario.hpp) → prepare (the model built once, the
// data simulated or taken as given) → run every observer on the same data → a result that holds
// every metric, and its JSON (summary.json's content, docs/cli.md "Output directories"). Nothing
// here prints or writes a file: `nlobs run` prints the result and writes its files, a binding
// hands it over. Warnings and progress go to the caller's callbacks.
#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "nlobs/observers/core/observer.hpp"
#include "nlobs/observers/core/simulation.hpp"
#include "nlobs/registry/model_registry.hpp"
#include "nlobs/runs/run_metrics.hpp"
#include "nlobs/runs/scenario.hpp"

namespace nlobs {

struct RunSettings {
  // Recorded measurements instead of a simulation (no truth: no errors), and what they came
  // from (summary.json's "source"); empty: the scenario is simulated.
  std::optional<Measurements> data{};
  std::string data_source = "simulation";
  // Window estimators record their engine's trace on their first window (the convergence plot).
  bool trace_first_window = false;
  // Called with (observer steps done, total) as the run goes; empty: none.
  std::function<void(long done, long total)> progress{};
  // Called with each warning as it is found: those of the observer types' reports and the
  // observers' own before the run (as they come, a repeated one repeated), then those the run
  // finds (not one given before); they are also kept in the result, in that order.
  std::function<void(const std::string&)> warning{};
};

// The scenario with its model and data: what every run of it (and every sweep value that keeps
// the data) starts from.
struct PreparedScenario {
  Scenario scenario;
  ModelInstance model;
  Measurements data;
  std::string source;      // "simulation" or RunSettings::data_source
  long settle_index = -1;  // the first sample of "after" (settle_time); −1: none set
};

// Builds the model (the one parse_scenario built, unless the scenario's model was edited) and
// simulates, or takes settings.data (moved: pass the settings with std::move to keep one copy
// of large data) after checking its sizes against the model. A simulation that leaves the
// model's domain ends early with data.stop_message set (no sample at all: run_prepared
// refuses it).
PreparedScenario prepare_scenario(Scenario scenario, RunSettings settings = {});

struct ScenarioRun {
  PreparedScenario prepared;
  RunResult result;  // names made unique, coordinate errors added (run_metrics.hpp)
  // What the scenario's observer types report before a run (the PI bounds), as summary.json's
  // "pi_bounds".
  nlohmann::json observer_reports = nlohmann::json::array();
  std::vector<std::string> warnings;
  std::vector<long> horizon_indices;  // per observer, the first sample with a full window
  // Per observer, the papers' figures (run_metrics.hpp: time to 1e-3, the MVT's residual, the
  // embedded and canonical coordinates' errors), computed once by run_prepared.
  std::vector<ObserverFigures> figures{};
};

// Runs every observer of the scenario on the prepared data. Throws std::runtime_error when the
// data has no sample (its stop message in the text), std::invalid_argument when a window is
// longer than the data, or an observer cannot be built (naming it).
ScenarioRun run_prepared(PreparedScenario prepared, const RunSettings& settings = {});
// prepare_scenario, then run_prepared.
ScenarioRun run_scenario(Scenario scenario, RunSettings settings = {});

// The run as summary.json holds it: per observer its metrics (MSE per state, iterations,
// failures, the papers' figures where they apply), the scenario's settings and the warnings.
nlohmann::json summary_json(const ScenarioRun& run);

// A number as JSON; null when it is not finite (JSON has no NaN or infinity).
nlohmann::json number_or_null(double v);

}  // namespace nlobs
