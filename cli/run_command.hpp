#pragma once
// `nlobs run SCENARIO [--steps N] [--noise SIGMA] [--seed S] [--out DIR] [--data FILE.csv]
//  [--sweep KEY=v1,v2,...] [--plot-timeout SECONDS]`.
#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>

namespace nlobs::cli {

struct RunOptions {
  std::optional<long> steps{};
  std::optional<double> noise{};
  std::optional<std::uint64_t> seed{};
  std::string out_dir{};    // empty: no files
  std::string data_file{};  // empty: simulate
  // The data file's times may go back (late rows, passed to the observers in file order).
  bool allow_late = false;
  // "theta=0.05,0.1,0.2": run the scenario's high_gain observers once per value on the same
  // data; "horizon=…" / "sample_period=…": the modulating observers (all observers run);
  // "PARAMETER=…": a model parameter, re-simulated per value. Prints and writes (with --out)
  // sweep.csv, sweep.dat and sweep.png instead of the usual outputs.
  std::string sweep{};
  // Seconds gnuplot may take to draw a run's (or a sweep's) plots before it is stopped and the
  // plots are skipped with a warning: (0, 86400].
  double plot_timeout = 120.0;
};

// Prints the table to `out` (progress and notices to `err`); writes the files when asked.
// Throws std::invalid_argument / std::runtime_error with a message naming what was wrong.
void run_scenario(const std::string& scenario, const RunOptions& options, std::ostream& out,
                  std::ostream& err);

}  // namespace nlobs::cli
