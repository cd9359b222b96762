// nlobs — command-line front end. Subcommands grow with the issues; see docs/cli.md.
#include <glog/logging.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "descriptor_buffer.hpp"
#include "list_command.hpp"
#include "nlobs/common/printable.hpp"
#include "nlobs/common/version.hpp"
#include "nlobs/reference/problem_suite.hpp"
#include "nlobs/reference/reference_engines.hpp"
#include "nlobs/registry/plugin.hpp"
#include "nlobs/registry/problem_sets.hpp"
#include "nlobs/runs/scenario.hpp"
#include "output_directory.hpp"
#include "run_command.hpp"
#include "solve_chua_window.hpp"
#include "suite_command.hpp"

namespace {

std::vector<std::string> specs_or(const std::string& list, std::vector<std::string> fallback) {
  if (list.empty()) return fallback;
  return nlobs::reference::split_spec_list(list);
}

}  // namespace

namespace {

constexpr int kCommandLineError = 1;  // an unknown option, a value that does not parse
constexpr int kRunError = 2;          // a scenario, data file or computation that failed

// A finite number in [min, max] (CLI::Range lets NaN through: every comparison with it is false),
// with the same message for inf and nan; above_min: in (min, max] (every positive subnormal is a
// positive number).
CLI::Validator finite_in(double min, double max, const std::string& description,
                         bool above_min = false) {
  return CLI::Validator(
      [min, max, above_min](std::string& text) {
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);  // ERANGE for a subnormal: still exact
        const bool ok = end != text.c_str() && *end == '\0' && std::isfinite(v) &&
                        (above_min ? v > min : v >= min) && v <= max;
        if (ok) return std::string();
        std::ostringstream os;
        os << "'" << nlobs::printable(text, 40) << "' is not a finite number ";
        if (max == std::numeric_limits<double>::max()) {
          os << (above_min ? "> " : ">= ") << min;
        } else {
          os << "in " << (above_min ? "(" : "[") << min << ", " << max << "]";
        }
        return os.str();
      },
      description);
}

// A decimal integer in [min, max]: CLI::Range said "Value abc not in range 1 to 1000000" of a
// word that is no number at all, and of 1e9. An integer beyond long's range is out of range
// too, not "not an integer".
CLI::Validator integer_in(long min, long max) {
  return CLI::Validator(
      [min, max](std::string& text) {
        errno = 0;
        char* end = nullptr;
        const long v = std::strtol(text.c_str(), &end, 10);
        const bool integer = end != text.c_str() && *end == '\0';
        if (integer && errno != ERANGE && v >= min && v <= max) return std::string();
        std::ostringstream os;
        os << "'" << nlobs::printable(text, 40) << "' is "
           << (integer ? "out of range: an integer in [" : "not an integer (one in [") << min
           << ", " << max << (integer ? "] is required" : "] is required)");
        return os.str();
      },
      "INT in " + std::to_string(min) + ".." + std::to_string(max));
}

// --seed: decimal digits only, within the generator's 64-bit range (no sign, no wrap-around,
// no saturation).
std::uint64_t parse_seed(const std::string& text) {
  const bool digits = !text.empty() && text.find_first_not_of("0123456789") == std::string::npos;
  errno = 0;
  char* end = nullptr;
  const unsigned long long v = digits ? std::strtoull(text.c_str(), &end, 10) : 0;
  if (!digits || errno == ERANGE || end == nullptr || *end != '\0') {
    throw std::invalid_argument("--seed '" + nlobs::printable(text, 40) +
                                "' is not an integer in 0..18446744073709551615");
  }
  return static_cast<std::uint64_t>(v);
}

// A terminal gets a line rewritten in place; a log (stderr redirected), a line every 10 s of a
// long suite, whatever stdout is.
nlobs::cli::SuiteArguments::Progress progress_mode() {
  return isatty(STDERR_FILENO) == 1 ? nlobs::cli::SuiteArguments::Progress::kTerminal
                                    : nlobs::cli::SuiteArguments::Progress::kLines;
}

// The options `nlobs suite` and `nlobs solve SET/NAME` share.
void add_suite_options(CLI::App* app, nlobs::cli::SuiteArguments& a) {
  app->add_option("--solvers,--engines", a.solvers,
                  "Comma-separated engine specs and references (default: the set's own list, "
                  "else the suite's; nlobs list engines)");
  app->add_option("--starts", a.starts, "Comma-separated start labels (default: all)");
  app->add_option("--threshold", a.threshold,
                  "Solved when |D_f F|2 <= this at the returned point (D_f: the problem's "
                  "f_scale, if any; default: the set's threshold, 1e-8)")
      ->check(finite_in(0.0, std::numeric_limits<double>::max(), "X > 0", true));
  app->add_option("--budget", a.evaluations_per_dimension,
                  "F evaluations per unknown and one (budget = this * (n + 1)); default 1000")
      ->check(integer_in(1L, 1000000L));
  app->add_flag("--json", a.json, "Print a JSON array instead of the tables");
  app->add_option("--csv", a.csv, "Also write the rows as CSV to FILE ('-': stdout, no table)");
  app->add_flag("--show-x", a.show_x, "Print each row's answer x below it in the table");
  app->add_flag("--monitor", a.monitor,
                "Print each iteration of our engines' solves on stderr (solver, problem/start, "
                "iteration, |step|, |F|); monitored solves are not repeated for their time");
  app->add_option("--time-limit", a.time_limit_s,
                  "Seconds each solve may take; past them its evaluations are refused and the "
                  "row is time_limit (default: none)")
      ->type_name("SECONDS")
      ->check(finite_in(1e-3, 86400.0, "SECONDS in 0.001..86400"));
}

int run_command_line(int argc, char** argv) {
  CLI::App app{"nlobs: nonlinear state estimation — solvers and observers"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "nlobs " NLOBS_VERSION_STRING);
  // Before or after the subcommand: `nlobs --plugin p.so run x.json`, `nlobs run --plugin ...`.
  app.fallthrough();
  std::vector<std::string> plugins;
  app.add_option("--plugin", plugins,
                 "Load a plugin (a shared library built with nlobs_add_plugin); repeatable. "
                 "NLOBS_PLUGIN_PATH (':'-separated files or directories) is loaded first")
      ->type_name("PATH")
      ->allow_extra_args(false);  // one path per --plugin: `run --plugin p.so x.json` keeps x.json

  // nlobs solve chua-window | nlobs solve PROBLEM...
  CLI::App* solve = app.add_subcommand(
      "solve",
      "Solve problems of a problem set (SET/NAME) with several engines beside KINSOL, "
      "MINPACK and GSL; or the chua-window table");
  solve->require_subcommand(0, 1);
  CLI::App* chua = solve->add_subcommand(
      "chua-window", "Modified-Chua window problem ([MGFF23]) with each engine and KINSOL");
  std::string engines_arg;
  double tolerance = 1e-8;
  bool chua_json = false;
  bool no_reference = false;
  chua->add_option("--engines", engines_arg,
                   "Comma-separated engine specs (default: picard,aitken,steffensen,anderson,"
                   "newton); see `nlobs list engines`; kinsol:fp, kinsol:fp-aa2, kinsol:newton");
  chua->add_option("--tol", tolerance,
                   "Step and residual tolerance (max norm); KINSOL gets "
                   "the same")
      ->default_val(1e-8);
  chua->add_flag("--json", chua_json, "Print a JSON array instead of the table");
  chua->add_flag("--no-reference", no_reference, "Leave out the KINSOL rows");
  std::vector<std::string> solve_selectors;
  nlobs::cli::SuiteArguments solve_args;
  solve->add_option("problems", solve_selectors,
                    "SET/NAME, SET/NAME:n=K or SET (nlobs list problems), one or more");
  add_suite_options(solve, solve_args);

  // nlobs suite SET
  CLI::App* suite = app.add_subcommand(
      "suite", "Run every listed solver on every (problem, start) of a problem set");
  std::string suite_set;
  nlobs::cli::SuiteArguments suite_args;
  // The built-in sets by name, read from the registry (a list written here went stale as sets
  // were added); a plugin's sets are loaded later and listed by `nlobs list problems`.
  suite
      ->add_option("set", suite_set,
                   "Problem set: " + nlobs::problem_set_registry().valid_list() +
                       ", or a plugin's (nlobs list problems); SET:n=K for a set of "
                       "run-time size (large:n=100000)")
      ->required();
  add_suite_options(suite, suite_args);

  // nlobs run
  CLI::App* run = app.add_subcommand("run", "Run a scenario: simulate, observe, measure");
  std::string scenario;
  long steps = 0;
  double noise = -1.0;
  std::string seed;  // parsed strictly below: CLI11 wraps "-1" and saturates 2^70
  nlobs::cli::RunOptions run_options;
  run->add_option("scenario", scenario, "Built-in scenario name or JSON scenario file")->required();
  CLI::Option* steps_opt = run->add_option("--steps", steps, "Number of samples")
                               ->check(integer_in(1L, nlobs::kMaxScenarioSteps));
  CLI::Option* noise_opt =
      run->add_option("--noise", noise, "Std. deviation of Gaussian measurement noise")
          ->check(finite_in(0.0, std::numeric_limits<double>::max(), "SIGMA >= 0"));
  CLI::Option* seed_opt = run->add_option("--seed", seed, "Seed of the noise generator");
  run->add_option("--out", run_options.out_dir,
                  "Directory for summary.json, trajectories.csv and PNG plots");
  run->add_option("--sweep", run_options.sweep,
                  "KEY=v1,v2,...: theta (high_gain: peaking vs noise), horizon or "
                  "sample_period (modulating), or a model parameter (re-simulated)");
  run->add_option("--plot-timeout", run_options.plot_timeout,
                  "Seconds gnuplot may take before the plots are skipped (default 120)")
      ->check(finite_in(1e-3, 86400.0, "SECONDS in 0.001..86400"));
  CLI::Option* data_opt = run->add_option(
      "--data", run_options.data_file,
      "Observe recorded measurements (CSV: t, y1..yp[, u1..um]) instead of simulating");
  run->add_flag("--allow-late", run_options.allow_late,
                "With --data: rows may come late (a time before an earlier row's); the MHE "
                "takes them into its horizon, other observers refuse them by name")
      ->needs(data_opt);

  // nlobs list
  CLI::App* list = app.add_subcommand("list", "List models, engines, observers, scenarios");
  std::string list_what;
  list->add_option("what", list_what, "models | engines | observers | scenarios (default: all)");

  // Exit status 1: the command line itself is wrong (docs/cli.md); 2: the run failed.
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : kCommandLineError;  // --help and --version exit 0
  }
  // Ceres logs failed evaluations through glog even when told to be silent; the statuses in
  // our tables already say what happened.
  FLAGS_minloglevel = google::GLOG_FATAL;
  // An interrupted run leaves no temporary files in its output directory.
  nlobs::cli::install_interrupt_cleanup();

  try {
    // The reference engines (KINSOL, MINPACK, GSL, PETSc) are engines by name everywhere below;
    // then plugins: their models, engines, observer types and problem sets are names like the
    // built-ins'. A refused plugin stops the run (kRunError).
    nlobs::reference::register_reference_engines();
    if (const char* path = std::getenv("NLOBS_PLUGIN_PATH"); path != nullptr && *path != '\0') {
      nlobs::load_plugin_path(path);
    }
    for (const std::string& plugin : plugins) nlobs::load_plugin(plugin);

    if (*chua) {
      const auto engines = specs_or(engines_arg, nlobs::cli::engine_names());
      const auto rows = nlobs::cli::solve_chua_window(engines, tolerance, !no_reference);
      if (chua_json) {
        std::cout << nlobs::cli::to_json(rows).dump(2) << '\n';
      } else {
        nlobs::cli::print_table(rows, tolerance, std::cout);
      }
    } else if (*solve) {
      if (solve_selectors.empty()) {
        std::cerr << "nlobs: error: nlobs solve needs chua-window or a problem: SET/NAME, "
                     "SET/NAME:n=K or SET (nlobs list problems)\n";
        return kCommandLineError;
      }
      solve_args.progress = progress_mode();
      nlobs::cli::run_problem_suite(solve_selectors, solve_args, "solve", std::cout, std::cerr);
    } else if (*suite) {
      suite_args.progress = progress_mode();
      nlobs::cli::run_problem_suite({suite_set}, suite_args, "suite", std::cout, std::cerr);
    } else if (*run) {
      if (*steps_opt) run_options.steps = steps;
      if (*noise_opt) run_options.noise = noise;
      if (*seed_opt) {
        try {
          run_options.seed = parse_seed(seed);
        } catch (const std::invalid_argument& e) {
          std::cerr << "nlobs: error: " << e.what() << '\n';
          return kCommandLineError;
        }
      }
      nlobs::cli::run_scenario(scenario, run_options, std::cout, std::cerr);
    } else if (*list) {
      nlobs::cli::print_list(list_what, std::cout);
    }
  } catch (...) {  // any type: a plugin's code may throw anything
    // Bounded and escaped: the message may carry a user's text (a name, a cell, an exception's).
    std::cerr << "nlobs: error: " << nlobs::current_exception_text(4000) << '\n';
    return kRunError;
  }
  return 0;
}

}  // namespace

// Standard output goes through a DescriptorBuffer, so that a write that fails (a full disk, a
// closed pipe: `nlobs suite mgh --json > /dev/full`) is an error naming the stream and the
// system's reason, never a run that exits 0 having lost its output.
int main(int argc, char** argv) {
  static nlobs::cli::DescriptorBuffer standard_output;  // outlives cout's flush at exit
  standard_output.attach(STDOUT_FILENO, isatty(STDOUT_FILENO) == 1);
  std::streambuf* const original = std::cout.rdbuf(&standard_output);
  int status = kRunError;
  try {
    status = run_command_line(argc, argv);
  } catch (...) {  // nothing may escape main without a word (CLI11's own exceptions included)
    std::cerr << "nlobs: error: " << nlobs::current_exception_text() << '\n';
  }
  std::cout.flush();
  if (!standard_output.drain() || !std::cout) {
    const int error = standard_output.error() != 0 ? standard_output.error() : EIO;
    std::cerr << "nlobs: error: writing standard output failed: " << std::strerror(error) << '\n';
    if (status == 0) status = kRunError;
  }
  std::cout.rdbuf(original);
  std::cerr.flush();
  if (!std::cerr && status == 0) status = kRunError;  // nothing left to say it with
  return status;
}
