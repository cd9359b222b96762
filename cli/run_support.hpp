#pragma once
// What `nlobs run`'s parts share (run_command.cpp, modulating_report.cpp).
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "nlobs/observers/core/simulation.hpp"
#include "run_command.hpp"
#include "scenario.hpp"

namespace nlobs::cli {

// `text` as one RFC 4180 field: quoted (inner quotes doubled) when it holds a comma, a quote,
// CR or LF; as it is otherwise.
std::string csv_field(std::string_view text);
nlohmann::json number_or_null(double v);
std::string fmt(double v, const char* f = "%.3e");  // "-" for non-finite values
bool have_gnuplot();                                // on PATH (gnuplot.hpp)
// Two observers of one name (two `ekf` entries) become "ekf" and "ekf #2" in every report, CSV
// column and plot: otherwise their columns, rows and keys would be indistinguishable.
void make_names_unique(RunResult& r);
// RunOptions::plot_timeout as a duration (validated by run_scenario: > 0, at most a day).
std::chrono::milliseconds plot_timeout(const RunOptions& options);
// "v1,v2,…" of `--sweep key=…`: finite numbers (> 0 when `positive`), at least one.
std::vector<double> parse_sweep_values(const std::string& key, const std::string& list,
                                       bool positive);
// The scenario's true system simulated (steps, noise, seed, input); a domain exit ends the data
// early with Measurements::stop_message set.
Measurements simulate_scenario(const Scenario& s, const AnyModel& model);
// Observers in other coordinates publish their estimate there as signals of kind
// kEmbeddedEstimate (ẑ, high gain) or kCanonicalEstimate (η̂, modulating functions): with the
// truth known, the error in those coordinates (through Observer::coordinates_at) becomes the
// signal "z_error" (kEmbeddedError) or "eta_error" (kCanonicalError, with the true norm
// "eta_norm", kCanonicalNorm).
void add_coordinate_errors(const Measurements& data,
                           const std::vector<std::unique_ptr<Observer>>& observers, RunResult& r);

// Per observer with an embedded error signal (kEmbeddedError, add_coordinate_errors): what
// [HG-EMB23]'s figures show.
struct EmbeddedMetrics {
  double max_zhat_norm = 0.0;  // the peaking: max_k ‖ẑ_k‖ over the kEmbeddedEstimate signals
  double final_z_error = NAN;
  double z_rms_after = NAN;
  double max_residual_after = NAN;  // of the kProjectionResidual signal (NaN without one)
  long time_index_below = -1;       // ‖z − ẑ‖ < 1e-6 from here to the end
  double jumps = 0.0;               // the kJumpCount signal's last value (0 without one)
};
std::optional<EmbeddedMetrics> embedded_metrics(const RunResult& r, size_t i);

}  // namespace nlobs::cli
