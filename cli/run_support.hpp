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
#include "nlobs/runs/run_metrics.hpp"
#include "nlobs/runs/scenario.hpp"
#include "nlobs/runs/scenario_run.hpp"
#include "nlobs/runs/sweep.hpp"
#include "run_command.hpp"

namespace nlobs::cli {

// `text` as one RFC 4180 field: quoted (inner quotes doubled) when it holds a comma, a quote,
// CR or LF; as it is otherwise.
std::string csv_field(std::string_view text);
std::string fmt(double v, const char* f = "%.3e");  // "-" for non-finite values
bool have_gnuplot();                                // on PATH (gnuplot.hpp)
// RunOptions::plot_timeout as a duration (validated by run_scenario: > 0, at most a day).
std::chrono::milliseconds plot_timeout(const RunOptions& options);
// "v1,v2,…" of `--sweep key=…`: finite numbers (> 0 when `positive`), at least one.
std::vector<double> parse_sweep_values(const std::string& key, const std::string& list,
                                       bool positive);
}  // namespace nlobs::cli
