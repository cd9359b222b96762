#pragma once
// What `nlobs run` reports for modulating-function observers ([MF-LTV]): canonical-state errors
// one horizon after start, Theorem 1's disturbance bound, and sweeps over the horizon, the
// sampling period or a model parameter (the disturbance level of Fig. 9).
#include <iosfwd>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "nlobs/observers/core/simulation.hpp"
#include "nlobs/runs/run_metrics.hpp"
#include "nlobs/runs/scenario.hpp"
#include "nlobs/runs/scenario_run.hpp"
#include "run_command.hpp"

namespace nlobs::cli {

// The canonical-state figures run_prepared computed (ScenarioRun::figures).
void print_modulating_metrics(const ScenarioRun& run, std::ostream& out);

// --sweep horizon=…, sample_period=… (the modulating observers' keys) or PARAMETER=… (the
// model's, re-simulating the data per value). Writes sweep.csv, sweep.dat, sweep.png with --out.
bool is_modulating_sweep(const std::string& key);
void run_modulating_sweep(const PreparedScenario& prepared, const std::string& key,
                          const std::vector<double>& values, const RunOptions& options,
                          std::ostream& out, std::ostream& err);

}  // namespace nlobs::cli
