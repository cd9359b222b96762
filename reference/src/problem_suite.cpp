#include "nlobs/reference/problem_suite.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>

#include "nlobs/reference/kinsol_solver.hpp"
#include "nlobs/reference/root_reference.hpp"
#include "nlobs/reference/timing.hpp"
#include "nlobs/solvers/engine_registry.hpp"
#include "nlobs/solvers/root_adapter.hpp"

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
  const auto refs = all_reference_solvers();
  return std::find(refs.begin(), refs.end(), s) != refs.end();
}

// The C libraries (MINPACK, GSL, KINSOL) must never see an exception unwind through them: their
// copies of a user's F, ∂F and G turn one into NaN, a non-finite evaluation they report.
RootProblem<Dynamic> guarded(const RootProblem<Dynamic>& f) {
  const RootProblem<Dynamic>* p = &f;
  return RootProblem<Dynamic>::with_jacobian(
      [p](const Eigen::VectorXd& x, Eigen::VectorXd& out) {
        try {
          p->evaluate(x, out);
        } catch (...) {
          out.setConstant(x.size(), std::numeric_limits<double>::quiet_NaN());
        }
      },
      [p](const Eigen::VectorXd& x, Eigen::MatrixXd& jac) {
        try {
          p->jacobian(x, jac);
        } catch (...) {
          jac.setConstant(x.size(), x.size(), std::numeric_limits<double>::quiet_NaN());
        }
      },
      f.size(), f.residual_size(), f.jacobian_source());
}
FixedPointProblem<Dynamic> guarded(const FixedPointProblem<Dynamic>& g) {
  const FixedPointProblem<Dynamic>* p = &g;
  return FixedPointProblem<Dynamic>::from_map(
      [p](const Eigen::VectorXd& x, Eigen::VectorXd& out) {
        try {
          p->evaluate(x, out);
        } catch (...) {
          out.setConstant(x.size(), std::numeric_limits<double>::quiet_NaN());
        }
      },
      g.size());
}

Outcome run_reference(const std::string& solver, const RootProblem<Dynamic>& residual,
                      const FixedPointProblem<Dynamic>& g, Eigen::VectorXd& x, long budget) {
  ReferenceOptions o;
  o.max_evaluations = budget;
  if (solver == "minpack:hybrj") {
    const ReferenceResult r = solve_minpack_hybrj(residual, x, o);
    return {r.status, r.f_evals, r.j_evals};
  }
  if (solver == "gsl:hybridsj" || solver == "gsl:gnewton") {
    const ReferenceResult r = solve_gsl(solver.substr(4), residual, x, o);
    return {r.status, r.f_evals, r.j_evals};
  }
  KinsolOptions ko;
  ko.strategy = KinsolSolver::strategy(solver).value_or(KinsolStrategy::kNewtonLineSearch);
  ko.tolerance = 1e-10;
  ko.max_iterations = budget;
  // KINSOL's own maximum step, 1000 ‖u₀‖₂, collapses to 1 at u₀ = 0 (Watson's start, a
  // user's zero start): the same rule measured from 1 instead (docs/solvers.md).
  ko.max_newton_step = 1000.0 * std::max(1.0, x.norm());
  const int n = static_cast<int>(residual.size());
  std::unique_ptr<KinsolSolver> k;
  if (ko.strategy == KinsolStrategy::kNewtonLineSearch) {
    const RootProblem<Dynamic>* f = &residual;
    k = std::make_unique<KinsolSolver>(
        n, ko, [f](const Eigen::VectorXd& v, Eigen::VectorXd& out) { f->evaluate(v, out); },
        [f](const Eigen::VectorXd& v, Eigen::MatrixXd& j) { f->jacobian(v, j); });
  } else {
    const FixedPointProblem<Dynamic>* gp = &g;
    k = std::make_unique<KinsolSolver>(
        n, ko, [gp](const Eigen::VectorXd& v, Eigen::VectorXd& out) { gp->evaluate(v, out); });
  }
  const KinsolResult r = k->solve(x);
  return {r.status(), r.evaluations, r.jacobian_evaluations};
}

double distance_to_solutions(const TestProblem& p, const Eigen::VectorXd& x) {
  if (p.solutions.empty()) return std::numeric_limits<double>::quiet_NaN();
  if (!x.allFinite()) return std::numeric_limits<double>::infinity();
  double best = std::numeric_limits<double>::infinity();
  for (const Eigen::VectorXd& s : p.solutions) {
    best = std::min(best, (x - s).lpNorm<Eigen::Infinity>());
  }
  return best;
}

bool selected(const ProblemStart& s, const SuiteOptions& options) {
  return options.starts.empty() ||
         std::find(options.starts.begin(), options.starts.end(), s.label) != options.starts.end();
}

}  // namespace

int count_suite_pairs(const std::vector<TestProblem>& problems, const SuiteOptions& options) {
  int total = 0;
  for (const TestProblem& p : problems) {
    for (const ProblemStart& s : p.starts) total += selected(s, options);
  }
  return total;
}

std::vector<std::string> default_suite_solvers() {
  std::vector<std::string> s = {"picard",
                                "aitken",
                                "steffensen",
                                "anderson",
                                "newton",
                                "newton:linesearch=1",
                                "newton:trustregion=1",
                                "dogleg",
                                "levenberg-marquardt",
                                "levenberg-marquardt:geodesic=1",
                                "pseudo-transient",
                                "auto",
                                "ceres",
                                "ceres:dogleg",
                                "nlopt:LD_SLSQP",
                                "nlopt:LN_BOBYQA"};
  for (const auto& r : reference_suite_solvers()) s.push_back(r);
  return s;
}

std::vector<std::string> reference_suite_solvers() {
  return {"minpack:hybrj", "kinsol:newton", "gsl:hybridsj", "gsl:gnewton"};
}

std::vector<std::string> all_reference_solvers() {
  std::vector<std::string> s = reference_suite_solvers();
  s.push_back("kinsol:fp");
  s.push_back("kinsol:fp-aa2");
  return s;
}

double suite_threshold(const ProblemSetEntry& set, const SuiteOptions& options) {
  const double t =
      std::isnan(options.solved_threshold) ? set.solved_threshold : options.solved_threshold;
  if (!(t > 0.0) || !std::isfinite(t)) {
    throw InvalidInput("the solved threshold on |F|2 must be finite and > 0 (got " +
                       std::to_string(t) + ")");
  }
  return t;
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

std::vector<SuiteRow> run_suite(const ProblemSetEntry& set,
                                const std::vector<TestProblem>& problems,
                                const std::vector<std::string>& solvers,
                                const SuiteOptions& options) {
  const double threshold = suite_threshold(set, options);
  if (options.evaluations_per_dimension < 1) {
    throw InvalidInput("the evaluation budget per dimension must be >= 1");
  }
  if (solvers.empty()) throw InvalidInput("no solver listed");
  auto& registry = EngineRegistry<Dynamic>::global();
  SolverOptions base;
  base.stop.step_tolerance = 1e-12;
  base.stop.residual_tolerance = 1e-10;
  // Validate every name and start label before running anything.
  for (const std::string& s : solvers) {
    if (is_reference(s)) continue;
    try {
      (void)registry.create(s, base);
    } catch (const InvalidInput& e) {
      std::string refs;
      for (const auto& r : all_reference_solvers()) refs += ", " + r;
      throw std::invalid_argument(std::string(e.what()) + "; references" + refs);
    }
  }
  std::set<std::string> labels;
  for (const TestProblem& p : problems) {
    for (const ProblemStart& s : p.starts) labels.insert(s.label);
  }
  for (const std::string& wanted : options.starts) {
    if (!labels.count(wanted)) {
      std::string valid;
      for (const auto& l : labels) valid += (valid.empty() ? "" : ", ") + l;
      throw std::invalid_argument("no problem of set '" + set.name + "' has a start '" +
                                  wanted.substr(0, 60) + "'; its starts: " + valid);
    }
  }
  const int total = count_suite_pairs(problems, options);

  int done = 0;
  std::vector<SuiteRow> rows;
  for (const TestProblem& p : problems) {
    const Index n = p.size();
    const long budget = options.evaluations_per_dimension * (n + 1);
    const FixedPointProblem<Dynamic> g =
        p.fixed_point ? *p.fixed_point : to_fixed_point<Dynamic>(p.residual);
    const RootProblem<Dynamic> safe_f = guarded(p.residual);
    const FixedPointProblem<Dynamic> safe_g = guarded(g);
    for (const ProblemStart& start : p.starts) {
      if (!selected(start, options)) continue;
      for (const std::string& s : solvers) {
        SuiteRow row;
        row.set = set.name;
        row.problem = p.name;
        row.n = static_cast<int>(n);
        row.start = start.label;
        row.start_scale = start.scale;
        row.solver = s;
        Eigen::VectorXd x = start.x;
        Outcome outcome;
        if (is_reference(s)) {
          row.ns = mean_ns_per_call(
              [&] {
                x = start.x;
                outcome = run_reference(s, safe_f, safe_g, x, budget);
              },
              kTimingNs, 1, kMaxTimedCalls);
        } else {
          SolverOptions o = base;
          o.stop.max_evaluations = static_cast<int>(std::min<long>(budget, 1L << 30));
          auto engine = registry.create(s, o);
          // The problem's box reaches the engines that take bounds; the others run unbounded
          // and are judged alike (outside_bounds).
          if ((p.lower.size() > 0 || p.upper.size() > 0) && engine->accepts_bounds()) {
            try {
              engine->set_bounds({p.lower, p.upper});
            } catch (const InvalidInput&) {  // levenberg-marquardt:geodesic=1, a user's engine
              row.status = "invalid_input";  // the engine refused the box: it did not run
              row.residual = std::numeric_limits<double>::infinity();
              row.error = std::numeric_limits<double>::infinity();
              rows.push_back(std::move(row));
              continue;
            }
          }
          row.ns = mean_ns_per_call(
              [&] {
                x = start.x;
                try {
                  const Summary sum = solve_or_report(*engine, g, x);
                  outcome = {std::string(to_string(sum.status)), sum.function_evaluations,
                             sum.jacobian_evaluations};
                } catch (const std::exception&) {  // a user's engine: a row, not the end
                  outcome = {"engine_threw", 0, 0};
                }
              },
              kTimingNs, 1, kMaxTimedCalls);
        }
        Eigen::VectorXd f(n);
        if (x.size() == n && x.allFinite()) {
          safe_f.evaluate(x, f);
          row.residual = f.allFinite() ? f.norm() : std::numeric_limits<double>::infinity();
        } else {
          row.residual = std::numeric_limits<double>::infinity();
        }
        row.status = outcome.status;
        const bool in_box = x.size() == n && !p.first_outside_bounds(x);
        if (!in_box) row.status = "outside_bounds";
        row.solved = in_box && row.residual <= threshold;
        row.error =
            x.size() == n ? distance_to_solutions(p, x) : std::numeric_limits<double>::infinity();
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
