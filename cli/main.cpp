// nlobs — command-line front end. Subcommands grow with the issues; see docs/cli.md.
#include <glog/logging.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <iostream>
#include <string>
#include <vector>

#include "list_command.hpp"
#include "reference/mgh_suite.hpp"
#include "solve_chua_window.hpp"
#include "suite_mgh.hpp"

namespace {

std::vector<std::string> specs_or(const std::string& list, std::vector<std::string> fallback) {
  if (list.empty()) return fallback;
  return nlobs::reference::split_spec_list(list);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"nlobs: nonlinear state estimation — solvers and observers"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "nlobs 0.1.0");

  // nlobs solve chua-window
  CLI::App* solve = app.add_subcommand("solve", "Solve a built-in problem with several engines");
  solve->require_subcommand(1);
  CLI::App* chua = solve->add_subcommand(
      "chua-window", "Modified-Chua window problem (METHODS §1) with each engine and KINSOL");
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

  // nlobs suite mgh
  CLI::App* suite = app.add_subcommand("suite", "Run a standard test suite");
  suite->require_subcommand(1);
  CLI::App* mgh = suite->add_subcommand(
      "mgh", "Moré-Garbow-Hillstrom systems of MINPACK's driver, starts x1, x10, x100");
  std::string solvers_arg;
  bool mgh_json = false;
  mgh->add_option("--solvers", solvers_arg,
                  "Comma-separated engine specs and references (default: all)");
  mgh->add_flag("--json", mgh_json, "Print a JSON array instead of the tables");

  // nlobs list
  CLI::App* list = app.add_subcommand("list", "List engines (and, later, models, observers)");
  std::string list_what;
  list->add_option("what", list_what, "engines (default: everything)");

  CLI11_PARSE(app, argc, argv);
  // Ceres logs failed evaluations through glog even when told to be silent; the statuses in
  // our tables already say what happened.
  FLAGS_minloglevel = google::GLOG_FATAL;

  try {
    if (*chua) {
      const auto engines = specs_or(engines_arg, nlobs::cli::engine_names());
      const auto rows = nlobs::cli::solve_chua_window(engines, tolerance, !no_reference);
      if (chua_json) {
        std::cout << nlobs::cli::to_json(rows).dump(2) << '\n';
      } else {
        nlobs::cli::print_table(rows, tolerance, std::cout);
      }
    } else if (*mgh) {
      nlobs::reference::SuiteOptions options;
      if (isatty(STDERR_FILENO))
        options.progress = [](int done, int total) {
          std::cerr << "\rnlobs suite mgh: " << done << "/" << total << " (problem, start) pairs"
                    << (done == total ? "\n" : "") << std::flush;
        };
      const auto rows = nlobs::reference::run_mgh_suite(
          specs_or(solvers_arg, nlobs::reference::default_suite_solvers()), options);
      if (mgh_json) {
        std::cout << nlobs::cli::suite_to_json(rows).dump(2) << '\n';
      } else {
        nlobs::cli::print_suite_tables(rows, std::cout);
      }
    } else if (*list) {
      nlobs::cli::print_list(list_what, std::cout);
    }
  } catch (const std::exception& e) {
    std::cerr << "nlobs: error: " << e.what() << '\n';
    return 2;
  }
  return 0;
}
