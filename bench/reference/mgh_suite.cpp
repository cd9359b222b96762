#include "reference/mgh_suite.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "nlobs/solvers/engine_registry.hpp"
#include "nlobs/solvers/root_adapter.hpp"
#include "reference/kinsol_solver.hpp"
#include "reference/mgh_problems.hpp"
#include "reference/root_reference.hpp"
#include "reference/timing.hpp"

namespace nlobs::reference {
namespace {

struct Outcome {
  std::string status;
  long f_evals = 0, j_evals = 0;
};

// Each (pair, solver) is timed over ~1 ms of repeated solves, at most 201 of them: the whole
// suite stays a few seconds.
constexpr double kTimingNs = 1e6;
constexpr long kMaxTimedCalls = 201;

bool is_reference(const std::string& s) {
  const auto refs = reference_suite_solvers();
  return std::find(refs.begin(), refs.end(), s) != refs.end();
}

Outcome run_reference(const std::string& solver, const MghCase& c, Eigen::VectorXd& x,
                      long budget) {
  ReferenceOptions o;
  o.max_evaluations = budget;
  Outcome out;
  if (solver == "minpack:hybrj") {
    const ReferenceResult r = solve_minpack_hybrj(c.problem, x, o);
    out = {r.status, r.f_evals, r.j_evals};
  } else if (solver == "gsl:hybridsj" || solver == "gsl:gnewton") {
    const ReferenceResult r = solve_gsl(solver.substr(4), c.problem, x, o);
    out = {r.status, r.f_evals, r.j_evals};
  } else {  // kinsol:newton
    KinsolOptions ko;
    ko.strategy = KinsolStrategy::kNewtonLineSearch;
    ko.tolerance = 1e-10;
    ko.max_iterations = budget;
    const RootProblem<Dynamic>* p = &c.problem;
    KinsolSolver solver_k(
        c.n, ko, [p](const Eigen::VectorXd& v, Eigen::VectorXd& f) { p->evaluate(v, f); },
        [p](const Eigen::VectorXd& v, Eigen::MatrixXd& j) { p->jacobian(v, j); });
    const KinsolResult r = solver_k.solve(x);
    out = {r.status(), r.evaluations, r.jacobian_evaluations};
  }
  return out;
}

}  // namespace

std::vector<std::string> default_suite_solvers() {
  std::vector<std::string> s = {
      "picard", "aitken",       "steffensen",     "anderson",       "newton", "newton:linesearch=1",
      "ceres",  "ceres:dogleg", "nlopt:LD_SLSQP", "nlopt:LN_BOBYQA"};
  for (const auto& r : reference_suite_solvers()) s.push_back(r);
  return s;
}

std::vector<std::string> reference_suite_solvers() {
  return {"minpack:hybrj", "kinsol:newton", "gsl:hybridsj", "gsl:gnewton"};
}

std::vector<std::string> split_spec_list(const std::string& list) {
  std::vector<std::string> out;
  size_t start = 0;
  while (start <= list.size()) {
    const size_t comma = list.find(',', start);
    const std::string item =
        list.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (!item.empty()) {
      const bool continues = item.find('=') != std::string::npos &&
                             item.find(':') == std::string::npos && !out.empty() &&
                             out.back().find(':') != std::string::npos;
      if (continues) {
        out.back() += "," + item;
      } else {
        out.push_back(item);
      }
    }
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

std::vector<SuiteRow> run_mgh_suite(const std::vector<std::string>& solvers,
                                    const SuiteOptions& options) {
  auto& registry = EngineRegistry<Dynamic>::global();
  SolverOptions base;
  base.stop.step_tolerance = 1e-12;
  base.stop.residual_tolerance = 1e-10;
  // Validate every name before running anything.
  for (const std::string& s : solvers) {
    if (is_reference(s)) continue;
    try {
      (void)registry.create(s, base);
    } catch (const InvalidInput& e) {
      std::string refs;
      for (const auto& r : reference_suite_solvers()) refs += ", " + r;
      throw std::invalid_argument(std::string(e.what()) + "; references" + refs);
    }
  }

  const std::vector<MghCase> cases = mgh_cases();
  const int total = static_cast<int>(cases.size() * options.start_scales.size());
  int done = 0;
  std::vector<SuiteRow> rows;
  for (const MghCase& c : cases) {
    const long budget = options.evaluations_per_dimension * (c.n + 1);
    const FixedPointProblem<Dynamic> fixed_point = to_fixed_point<Dynamic>(c.problem);
    for (double scale : options.start_scales) {
      const Eigen::VectorXd x0 = c.start(scale);
      for (const std::string& s : solvers) {
        SuiteRow row;
        row.problem = c.name;
        row.n = c.n;
        row.start_scale = scale;
        row.solver = s;
        Eigen::VectorXd x = x0;
        Outcome outcome;
        if (is_reference(s)) {
          row.ns = mean_ns_per_call(
              [&] {
                x = x0;
                outcome = run_reference(s, c, x, budget);
              },
              kTimingNs, 1, kMaxTimedCalls);
        } else {
          SolverOptions o = base;
          o.stop.max_evaluations = static_cast<int>(budget);
          auto engine = registry.create(s, o);
          row.ns = mean_ns_per_call(
              [&] {
                x = x0;
                const Summary sum = solve_or_report(*engine, fixed_point, x);
                outcome = {std::string(to_string(sum.status)), sum.function_evaluations,
                           sum.jacobian_evaluations};
              },
              kTimingNs, 1, kMaxTimedCalls);
        }
        Eigen::VectorXd f(c.n);
        c.problem.evaluate(x, f);
        row.residual =
            f.allFinite() && x.allFinite() ? f.norm() : std::numeric_limits<double>::infinity();
        row.solved = row.residual <= options.solved_threshold;
        row.status = outcome.status;
        row.f_evals = outcome.f_evals;
        row.j_evals = outcome.j_evals;
        rows.push_back(std::move(row));
      }
      if (options.progress) options.progress(++done, total);
    }
  }
  return rows;
}

}  // namespace nlobs::reference
