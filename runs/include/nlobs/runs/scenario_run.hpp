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

struct PreparedScenario;

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
  // Called by prepare_request and run_request once the scenario is parsed and its overrides
  // checked, before any data is read or simulated (`nlobs run` takes its --out lock here: a bad
  // scenario leaves no directory behind); empty: none.
  std::function<void(const Scenario&)> parsed{};
  // Called by run_request once the data is ready (simulated or read), before the observers run:
  // a simulation that stopped early says why in data.stop_message, even when the run then fails
  // (too few samples for a window); empty: none.
  std::function<void(const PreparedScenario&)> prepared{};
};

// The scenario with its model and data: what every run of it (and every sweep value that keeps
// the data) starts from.
struct PreparedScenario {
  Scenario scenario;
  ModelInstance model;
  Measurements data;
  std::string source;      // "simulation" or RunSettings::data_source
  long settle_index = -1;  // the first sample of "after" (settle_time); −1: none set
  // The data were simulated (with the scenario's noise, which observers may then take as
  // declared), not recorded.
  bool simulated = false;
};

// Builds the model (the one parse_scenario built, unless the scenario's model was edited) and
// simulates, or takes settings.data (moved: pass the settings with std::move to keep one copy
// of large data) after checking its sizes against the model. A simulation that leaves the
// model's domain ends early with data.stop_message set (no sample at all: run_prepared
// refuses it).
PreparedScenario prepare_scenario(Scenario scenario, RunSettings settings = {});

// A scenario as a program asks for it: by built-in name or JSON file, with the overrides of
// `nlobs run` (--steps, --noise, --seed, --data, --allow-late) or a binding's keywords, each
// checked by prepare_request and a refusal naming the field ('steps' = 0 is out of range: ...).
struct ScenarioRequest {
  std::string scenario;
  std::optional<long> steps{};          // 1..kMaxScenarioSteps
  std::optional<double> noise{};        // σ of the measurement noise: finite, ≥ 0
  std::optional<std::uint64_t> seed{};  // of the noise
  // Recorded measurements (nlobs/runs/measurements_file.hpp) read with the model's sizes,
  // instead of a simulation; empty: simulated (or RunSettings::data, when given).
  std::string data_file{};
  bool allow_late = false;  // data_file's rows may come at or before an earlier row's time
};

// load_scenario, the request's overrides, settings.parsed, its data file read for the model
// parse_scenario built (not built again), then prepare_scenario with `settings` (a data file and
// settings.data together are refused). A simulation that leaves the model's domain ends early,
// as prepare_scenario's.
PreparedScenario prepare_request(const ScenarioRequest& request, RunSettings settings = {});

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
// prepare_request, settings.prepared, then run_prepared: the one call `nlobs run` makes into
// this layer.
ScenarioRun run_request(const ScenarioRequest& request, RunSettings settings = {});

// The run as summary.json holds it: per observer its metrics (MSE per state, iterations,
// failures, the papers' figures where they apply), the scenario's settings and the warnings.
nlohmann::json summary_json(const ScenarioRun& run);

// A number as JSON; null when it is not finite (JSON has no NaN or infinity).
nlohmann::json number_or_null(double v);

}  // namespace nlobs
