#include "solve_chua_window.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <ostream>
#include <stdexcept>

#include "nlobs/common/printable.hpp"
#include "nlobs/reference/reference_engines.hpp"
#include "nlobs/reference/timing.hpp"
#include "nlobs/registry/problem_sets/chua_window_set.hpp"
#include "nlobs/solvers/engine_registry.hpp"

namespace nlobs::cli {
namespace {

// `spec` as the row runs it: KINSOL (any kinsol engine) gets --tol as its fnormtol and
// scsteptol, as the engines get it as their step and residual tolerances.
std::string with_tolerance(const std::string& spec, double tol) {
  if (spec.rfind("kinsol", 0) != 0 || spec.find("residual_tolerance") != std::string::npos) {
    return spec;
  }
  char value[32];
  std::snprintf(value, sizeof value, "%.17g", tol);
  return spec + (spec.find(':') == std::string::npos ? ":" : ",") + "residual_tolerance=" + value;
}

// One row: any engine by name, KINSOL's among them (reference_engines.hpp), at size 3 (the
// reference engines through the registry's Dynamic fallback).
SolveRow run_engine(const std::string& name, const reference::ChuaWindowCase& c, double tol) {
  SolverOptions options;
  options.stop.step_tolerance = tol;      // KINSOL's scsteptol
  options.stop.residual_tolerance = tol;  // KINSOL's fnormtol
  try {
    std::unique_ptr<Engine<3>> engine =
        EngineRegistry<3>::global().create(with_tolerance(name, tol), options);
    Vector<3> x = c.initial_guess;
    const Summary s = engine->solve(c.problem, x);
    SolveRow row{name,
                 s.library_status.empty() ? std::string(to_string(s.status)) : s.library_status,
                 s.iterations,
                 s.function_evaluations,
                 x,
                 (x - c.true_state).lpNorm<Eigen::Infinity>(),
                 0.0,
                 {}};
    // At least 3 solves and 20 ms in total.
    row.ns_per_solve = reference::mean_ns_per_call(
        [&] {
          Vector<3> xr = c.initial_guess;
          engine->solve(c.problem, xr);
        },
        2e7, 3);
    return row;
  } catch (...) {
    // F is ours; an engine of a user's (a plugin's) may throw anything: a row, as in
    // `nlobs suite` (engine_threw), never the end of the run.
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return {name,
            "engine_threw",
            0,
            0,
            Eigen::Vector3d::Constant(nan),
            nan,
            0.0,
            name + " threw: " + current_exception_text()};
  }
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& e : v) s += (s.empty() ? "" : ", ") + e;
  return s;
}

}  // namespace

const std::vector<std::string>& engine_names() {
  static const std::vector<std::string> names = {"picard", "aitken", "steffensen", "anderson",
                                                 "newton"};
  return names;
}

const std::vector<std::string>& reference_names() {
  static const std::vector<std::string> names = {"kinsol:fp", "kinsol:fp-aa2", "kinsol:newton"};
  return names;
}

std::vector<SolveRow> solve_chua_window(const std::vector<std::string>& engines, double tolerance,
                                        bool with_reference) {
  if (!(std::isfinite(tolerance) && tolerance > 0.0)) {
    throw std::invalid_argument("--tol " + std::to_string(tolerance) +
                                " is invalid: must be finite and > 0");
  }
  reference::register_reference_engines();
  const auto& refs = reference_names();
  std::vector<std::string> order;
  for (const std::string& e : engines) {
    try {
      (void)EngineRegistry<3>::global().create(with_tolerance(e, tolerance));  // name, options
    } catch (const InvalidInput& error) {
      throw std::invalid_argument(std::string(error.what()) + "; references: " + join(refs));
    }
    if (std::find(order.begin(), order.end(), e) == order.end()) order.push_back(e);
  }
  if (with_reference) {
    for (const std::string& r : refs) {
      if (std::find(order.begin(), order.end(), r) == order.end()) order.push_back(r);
    }
  }
  const reference::ChuaWindowCase c;
  std::vector<SolveRow> rows;
  for (const std::string& e : order) {
    rows.push_back(run_engine(e, c, tolerance));
  }
  return rows;
}

void print_table(const std::vector<SolveRow>& rows, double tolerance, std::ostream& out) {
  char line[256];
  std::snprintf(line, sizeof line,
                "modified-Chua window ([MGFF23]): x_true = [1, 2.1428, -0.1648], "
                "x0 = [5, 10, -5], tol = %g\n",
                tolerance);
  out << line;
  std::snprintf(line, sizeof line, "%-24s %-17s %6s %6s  %-34s %10s %12s\n", "engine", "status",
                "iter", "evals", "solution", "|x-x*|inf", "ns/solve");
  out << line;
  for (const SolveRow& r : rows) {
    char sol[64];
    std::snprintf(sol, sizeof sol, "[%.6f, %.6f, %.6f]", r.solution[0], r.solution[1],
                  r.solution[2]);
    std::snprintf(line, sizeof line, "%-24s %-17s %6ld %6ld  %-34s %10.2e %12.0f\n",
                  r.engine.c_str(), r.status.c_str(), r.iterations, r.evaluations, sol, r.error,
                  r.ns_per_solve);
    out << line;
  }
  for (const SolveRow& r : rows) {
    if (!r.message.empty()) out << r.message << '\n';
  }
}

nlohmann::json to_json(const std::vector<SolveRow>& rows) {
  nlohmann::json a = nlohmann::json::array();
  for (const SolveRow& r : rows) {
    a.push_back({{"engine", r.engine},
                 {"status", r.status},
                 {"iterations", r.iterations},
                 {"evaluations", r.evaluations},
                 {"solution", {r.solution[0], r.solution[1], r.solution[2]}},
                 {"error", r.error},
                 {"ns_per_solve", r.ns_per_solve}});
    if (!r.message.empty()) a.back()["message"] = r.message;
  }
  return a;
}

}  // namespace nlobs::cli
