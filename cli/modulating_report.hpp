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
#include "run_command.hpp"
#include "scenario.hpp"

namespace nlobs::cli {

// Per observer with a canonical error signal (kCanonicalError and kCanonicalNorm, added by
// add_coordinate_errors).
struct ModulatingMetrics {
  double rel_after_horizon = NAN;  // max ‖η − η̂‖ / max ‖η‖ over samples from one horizon on
  double abs_after_horizon = NAN;  // the same, absolute (summary: max_eta_error_after_horizon)
  double final_rel = NAN;          // the same over the last 10 % of the run
  double eta_rms_after = NAN;      // RMS of ‖η − η̂‖ from the settle index on
  double max_bound = NAN;          // largest Theorem 1 bound (the kCanonicalBound signal), if any
};
std::optional<ModulatingMetrics> modulating_metrics(const RunResult& r, size_t i,
                                                    long horizon_index);

void print_modulating_metrics(const RunResult& r, const std::vector<long>& horizon_indices,
                              std::ostream& out);
void add_modulating_json(const RunResult& r, size_t i, long horizon_index, nlohmann::json& o);

// --sweep horizon=…, sample_period=… (the modulating observers' keys) or PARAMETER=… (the
// model's, re-simulating the data per value). Writes sweep.csv, sweep.dat, sweep.png with --out.
bool is_modulating_sweep(const std::string& key);
void run_modulating_sweep(const Scenario& s, const std::string& key,
                          const std::vector<double>& values, const Measurements& data,
                          long settle_index, const RunOptions& options, std::ostream& out,
                          std::ostream& err);

}  // namespace nlobs::cli
