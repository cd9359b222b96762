#pragma once
// What `nlobs run`'s parts share (run_command.cpp, modulating_report.cpp).
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "nlobs/observers/simulation.hpp"
#include "scenario.hpp"

namespace nlobs::cli {

// Writes through a temporary name and renames at the end: nothing half-written looks complete.
void write_atomically(const std::filesystem::path& path, const std::string& content);
// `text` as one RFC 4180 field: quoted (inner quotes doubled) when it holds a comma, a quote,
// CR or LF; as it is otherwise.
std::string csv_field(std::string_view text);
nlohmann::json number_or_null(double v);
std::string fmt(double v, const char* f = "%.3e");  // "-" for non-finite values
bool have_gnuplot();                                // on PATH (gnuplot.hpp)
// --out DIR made absolute and created (gnuplot runs inside it: scripts name files relative to it).
std::filesystem::path output_directory(const std::string& out_dir);
// sweep.png from `script` (run_gnuplot_script, gnuplot.hpp): ", sweep.png" to `out` when drawn,
// else a warning naming why to `err` (plots are best-effort).
void plot_sweep(const std::filesystem::path& dir, const std::string& script, std::ostream& out,
                std::ostream& err);
// "v1,v2,…" of `--sweep key=…`: finite numbers (> 0 when `positive`), at least one.
std::vector<double> parse_sweep_values(const std::string& key, const std::string& list,
                                       bool positive);
// The scenario's true system simulated (steps, noise, seed, input); a domain exit ends the data
// early with Measurements::stop_message set.
Measurements simulate_scenario(const Scenario& s, const AnyModel& model);
// Observers in other coordinates publish their estimate there as extras zhat1… (high gain) or
// eta1… (modulating functions): with the truth known, the error in those coordinates becomes
// the extra "z_error" or "eta_error" (and, for eta, the true norm "eta_norm").
void add_coordinate_errors(const Measurements& data,
                           const std::vector<std::unique_ptr<Observer>>& observers, RunResult& r);

}  // namespace nlobs::cli
