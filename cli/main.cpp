// nlobs — command-line front end. Subcommands grow with the issues; see docs/cli.md.
#include <CLI/CLI.hpp>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "solve_chua_window.hpp"

int main(int argc, char** argv) {
  CLI::App app{"nlobs: nonlinear state estimation — solvers and observers"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "nlobs 0.1.0");

  CLI::App* solve = app.add_subcommand("solve", "Solve a built-in problem with several engines");
  solve->require_subcommand(1);
  CLI::App* chua = solve->add_subcommand(
      "chua-window", "Modified-Chua window problem (METHODS §1) with each engine and KINSOL");
  std::string engines_arg;
  double tolerance = 1e-8;
  bool json = false;
  bool no_reference = false;
  std::ostringstream valid;
  for (const auto& n : nlobs::cli::engine_names()) valid << n << ' ';
  chua->add_option("--engines", engines_arg,
                   "Comma-separated engines (default: all): " + valid.str() +
                       "kinsol:fp kinsol:fp-aa2 kinsol:newton");
  chua->add_option("--tol", tolerance, "Step tolerance (max norm); KINSOL gets the same")
      ->default_val(1e-8);
  chua->add_flag("--json", json, "Print a JSON array instead of the table");
  chua->add_flag("--no-reference", no_reference, "Leave out the KINSOL rows");

  CLI11_PARSE(app, argc, argv);

  try {
    std::vector<std::string> engines;
    if (engines_arg.empty()) {
      engines = nlobs::cli::engine_names();
    } else {
      std::stringstream ss(engines_arg);
      for (std::string item; std::getline(ss, item, ',');) {
        if (!item.empty()) engines.push_back(item);
      }
    }
    const auto rows = nlobs::cli::solve_chua_window(engines, tolerance, !no_reference);
    if (json) {
      std::cout << nlobs::cli::to_json(rows).dump(2) << '\n';
    } else {
      nlobs::cli::print_table(rows, tolerance, std::cout);
    }
  } catch (const std::exception& e) {
    std::cerr << "nlobs: error: " << e.what() << '\n';
    return 2;
  }
  return 0;
}
