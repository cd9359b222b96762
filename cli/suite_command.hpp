#pragma once
// `nlobs suite SET` and `nlobs solve SET/NAME …`: problems of the problem-set registry with every
// listed engine and reference solver, one table (or JSON, or CSV).
#include <iosfwd>
#include <limits>
#include <string>
#include <vector>

namespace nlobs::cli {

struct SuiteArguments {
  // Comma list of engine specs and references; empty: each set's default_solvers, else the
  // suite's default list.
  std::string solvers{};
  std::string starts{};  // comma list of start labels; empty: every start
  double threshold = std::numeric_limits<double>::quiet_NaN();  // NaN: each set's own
  long evaluations_per_dimension = 1000;
  bool json = false;
  std::string csv{};    // a file to write the CSV to ("-": stdout); empty: none
  bool show_x = false;  // the table prints each row's answer x on the line below it
  // Wall time per solve (reference::SuiteOptions::time_limit_s); +inf: none.
  double time_limit_s = std::numeric_limits<double>::infinity();
  // Progress on `err`: none; one line rewritten after every (problem, start) pair (a
  // terminal); or, for a log, a line per pair at most every progress_interval_s seconds, the
  // first after that long (a short suite prints none).
  enum class Progress { kNone, kTerminal, kLines };
  Progress progress = Progress::kNone;
  double progress_interval_s = 10.0;
  // --monitor: a line on `err` after each iteration of each of our engines' solves (solver,
  // problem/start, iteration, |step|, |F|); a monitored solve runs once, not repeated for its
  // time, and the progress line is left out.
  bool monitor = false;
};

// Runs every selector ("SET", "SET:n=K", "SET/NAME", "SET/NAME:n=K") in turn and prints the table
// (or the JSON array) to `out`; `command` ("suite" or "solve") names the command in messages.
// Throws std::invalid_argument (an unknown set, problem, solver or start, a bad threshold) before
// anything runs.
void run_problem_suite(const std::vector<std::string>& selectors, const SuiteArguments& args,
                       const std::string& command, std::ostream& out, std::ostream& err);

}  // namespace nlobs::cli
