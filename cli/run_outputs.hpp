#pragma once
// The files of `nlobs run --out DIR` (docs/cli.md "Output directories"), written through
// OutputDirectory (temporary names, stale files removed, summary.json last).
#include <Eigen/Core>
#include <chrono>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include "nlobs/observers/core/simulation.hpp"
#include "nlobs/runs/scenario.hpp"
#include "output_directory.hpp"

namespace nlobs::cli {

// At most this many rows in plot_data.csv: longer runs are reduced to the minimum and the
// maximum of every column over kPlotRows / 2 equal spans of samples, so that a plot keeps
// every excursion (a spike of one sample stays visible) at a fixed cost.
inline constexpr Eigen::Index kPlotRows = 4000;

// Columns of a table: `columns` of them, column j's value at sample k by value(j, k).
struct ColumnTable {
  Eigen::Index columns = 0, rows = 0;
  std::function<double(Eigen::Index column, Eigen::Index row)> value;
};

// Every row of `table` as CSV (12 significant digits, "nan" for NaN) after `header`, streamed.
void write_csv_rows(std::ostream& out, const std::string& header, const ColumnTable& table);
// The same reduced for plotting: all rows up to kPlotRows, else per span two rows, the first at
// the span's first time with every column's minimum, the second at its last time with the
// maxima (NaN ignored; NaN when a span has no number). Column 0 must be the time.
void write_plot_rows(std::ostream& out, const std::string& header, const ColumnTable& table);

// Writes trajectories.csv (every sample), plot_data.csv (reduced; the plots read it),
// first_window.dat, scenario.json and, when gnuplot is on PATH, the PNG plots (best-effort: a
// failure or a timeout becomes a warning in `warnings` and on `err`). Returns the plots drawn.
std::vector<std::string> write_run_files(OutputDirectory& dir, const Scenario& s,
                                         const Measurements& data, const RunResult& r,
                                         std::chrono::milliseconds plot_timeout,
                                         std::vector<std::string>& warnings, std::ostream& err);

// A sweep's files: sweep.dat, sweep.png (from `plot_commands`, the gnuplot commands after the
// terminal and output are set; best-effort), then sweep.csv last, which marks the directory
// complete. Prints "wrote …" to `out`.
void write_sweep_files(OutputDirectory& dir, const std::string& csv, const std::string& dat,
                       const std::string& plot_commands, std::chrono::milliseconds plot_timeout,
                       std::ostream& out, std::ostream& err);

}  // namespace nlobs::cli
