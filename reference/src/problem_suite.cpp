#include "nlobs/reference/problem_suite.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <new>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "nlobs/common/printable.hpp"
#include "nlobs/reference/kinsol_solver.hpp"
#include "nlobs/reference/petsc_solver.hpp"
#include "nlobs/reference/root_reference.hpp"
#include "nlobs/reference/timing.hpp"
#include "nlobs/solvers/engine_registry.hpp"
#include "nlobs/solvers/root_adapter.hpp"
#include "nlobs/solvers/sparse/pattern_bandwidths.hpp"
#include "nlobs/solvers/sparse/sparse_jacobian.hpp"
#include "nlobs/solvers/sparse/sparsity_pattern.hpp"
#include "petsc_option_rules.hpp"

namespace nlobs::reference {
namespace {

// A closed box inside the problem's: each strict bound √ε · max(1, |bound|) inward. For the
// engines whose boxes are closed (Ceres, NLopt): they never evaluate F on a strict bound either.
// One ulp inward is not enough: where F is ln c, its derivative 1/c at c = 5e-324 is infinite,
// and a method that jumps to the bound (NLopt's SLSQP does) stops on a non-finite Jacobian.
BoxBounds closed_inside(const TestProblem& p) {
  BoxBounds box{p.lower, p.upper};
  const double margin = std::sqrt(std::numeric_limits<double>::epsilon());
  auto inward = [margin](double bound, double towards) {
    return bound + std::copysign(margin * std::max(1.0, std::abs(bound)), towards);
  };
  // Never past the other side (or its own inward point): the box stays valid, if thin.
  const Index n = std::max(p.lower.size(), p.upper.size());
  auto other = [&](const Eigen::VectorXd& side, Index i, double none) {
    return side.size() == n ? side[i] : none;
  };
  const double inf = std::numeric_limits<double>::infinity();
  for (Index i = 0; i < p.strict_lower.size(); ++i) {
    if (p.strict_lower[i] && std::isfinite(box.lower[i])) {
      box.lower[i] = std::min(inward(box.lower[i], 1.0), other(p.upper, i, inf));
    }
  }
  for (Index i = 0; i < p.strict_upper.size(); ++i) {
    if (p.strict_upper[i] && std::isfinite(box.upper[i])) {
      box.upper[i] = std::max(inward(box.upper[i], -1.0), other(box.lower, i, -inf));
    }
  }
  return box;
}

struct Outcome {
  std::string status;
  long f_evals = 0, j_evals = 0;
  std::string message;
};

// Each (pair, solver) is timed over ~1 ms of repeated solves, at most 201 of them: the whole
// suite stays a few seconds.
constexpr double kTimingNs = 1e6;
constexpr long kMaxTimedCalls = 201;

bool is_reference(const std::string& s) {
  if (PetscSnesSolver::is_name(s)) return true;  // any petsc:TYPE[:-key=value...]
  const auto refs = all_reference_solvers();
  return std::find(refs.begin(), refs.end(), s) != refs.end();
}

// A fall of ‖F‖ counts when it goes below (1 − this) × the value at the fall before it, as the
// engines' progress window has it (ProgressWindow): rounding-level jitter near a root is none.
constexpr double kMeaningfulFall = kMeaningfulResidualFall;

// Counts the evaluations of F (or G) one solve makes and refuses those beyond its budget or past
// its deadline: the refused call returns NaN without calling the problem, and the row becomes
// max_evaluations or time_limit.
struct Meter {
  using Clock = std::chrono::steady_clock;
  long count = 0;
  long cap = std::numeric_limits<long>::max();
  bool refused = false;    // an evaluation beyond the budget was asked for
  bool timed_out = false;  // an evaluation past the deadline was asked for
  int late_calls = 0;      // evaluations asked for past the deadline
  bool timed = false;
  Clock::time_point deadline{};
  double time_limit_s = 0.0;
  // Progress, as the engines' StopCriteria::progress_window counts it: the count at the last
  // evaluation that brought ‖D_f F‖₂ below (1 − kMeaningfulFall) × its value at the fall before
  // (the anchor). A slow but steady descent makes progress; jitter at a floor does not.
  const Eigen::VectorXd* f_scale = nullptr;
  double anchor = std::numeric_limits<double>::infinity();
  long last_fall = 0;
  Eigen::VectorXd scratch, residual;
  void reset(long budget, double limit_s) {
    count = 0;
    cap = budget;
    refused = timed_out = false;
    late_calls = 0;
    anchor = std::numeric_limits<double>::infinity();
    last_fall = 0;
    timed = std::isfinite(limit_s);
    time_limit_s = limit_s;
    if (timed) {
      deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                    std::chrono::duration<double>(limit_s));
    }
  }
  // True when the deadline has passed (and notes it).
  bool late() {
    if (!timed || Clock::now() < deadline) return false;
    timed_out = true;
    ++late_calls;
    return true;
  }
  // After the evaluation just taken: f = F(x) (NaN or inf: no progress).
  void saw(const Eigen::VectorXd& f) {
    if (!f.allFinite()) return;
    double norm = f.stableNorm();
    if (f_scale && f_scale->size() == f.size()) {
      scratch = f.cwiseProduct(*f_scale);
      norm = scratch.stableNorm();
    }
    if (norm < (1.0 - kMeaningfulFall) * anchor) {
      anchor = norm;
      last_fall = count;
    }
  }
  // After an evaluation of G: F = G(x) − x.
  void saw_fixed_point(const Eigen::VectorXd& x, const Eigen::VectorXd& g) {
    if (g.size() != x.size()) return;  // the engine names a G of the wrong size
    residual = g - x;
    saw(residual);
  }
  // Evaluations made since ‖D_f F‖ last fell meaningfully (all of them if it never did).
  long past_progress() const { return count - last_fall; }
  // True when one more evaluation is within the budget and the time limit (and counts it).
  bool take() {
    if (count >= cap) {
      refused = true;
      return false;
    }
    if (late()) return false;
    ++count;
    return true;
  }
};

// Thrown from G into our engines (never into the C libraries) when one keeps asking for
// evaluations past the time limit: it would otherwise hold the suite.
struct TimeLimitStop {};
constexpr int kLateCallsBeforeStop = 10;

// The C libraries (MINPACK, GSL, KINSOL) must never see an exception unwind through them: their
// copies of a user's F, ∂F and G turn one into NaN, a non-finite evaluation they report. With a
// meter, an evaluation beyond its budget is NaN too (the references stop before, each counting
// its own: the meter is the backstop).
RootProblem<Dynamic> guarded(const RootProblem<Dynamic>& f, Meter* meter) {
  const RootProblem<Dynamic>* p = &f;
  return RootProblem<Dynamic>::with_jacobian(
      [p, meter](const Eigen::VectorXd& x, Eigen::VectorXd& out) {
        if (meter && !meter->take()) {
          out.setConstant(p->residual_size(), std::numeric_limits<double>::quiet_NaN());
          return;
        }
        try {
          p->evaluate(x, out);
        } catch (...) {
          out.setConstant(p->residual_size(), std::numeric_limits<double>::quiet_NaN());
        }
        if (meter) meter->saw(out);
      },
      [p, meter](const Eigen::VectorXd& x, Eigen::MatrixXd& jac) {
        if (meter && meter->late()) {
          jac.setConstant(p->residual_size(), x.size(), std::numeric_limits<double>::quiet_NaN());
          return;
        }
        try {
          p->jacobian(x, jac);
        } catch (...) {
          jac.setConstant(p->residual_size(), x.size(), std::numeric_limits<double>::quiet_NaN());
        }
      },
      f.size(), f.residual_size(), f.jacobian_source());
}
FixedPointProblem<Dynamic> guarded(const FixedPointProblem<Dynamic>& g, Meter* meter) {
  const FixedPointProblem<Dynamic>* p = &g;
  return FixedPointProblem<Dynamic>::from_map(
      [p, meter](const Eigen::VectorXd& x, Eigen::VectorXd& out) {
        if (meter && !meter->take()) {
          out.setConstant(p->size(), std::numeric_limits<double>::quiet_NaN());
          return;
        }
        try {
          p->evaluate(x, out);
        } catch (...) {
          out.setConstant(p->size(), std::numeric_limits<double>::quiet_NaN());
        }
        if (meter) meter->saw_fixed_point(x, out);
      },
      g.size());
}

// G for our engines (a user's among them): metered, its Jacobian kept, its exceptions left to
// the engine (an engine that throws is a row, engine_threw).
FixedPointProblem<Dynamic> metered(const FixedPointProblem<Dynamic>& g, Meter& meter) {
  const FixedPointProblem<Dynamic>* p = &g;
  auto map = [p, &meter](const Eigen::VectorXd& x, Eigen::VectorXd& out) {
    if (!meter.take()) {
      if (meter.late_calls > kLateCallsBeforeStop) throw TimeLimitStop{};
      out.setConstant(p->size(), std::numeric_limits<double>::quiet_NaN());
      return;
    }
    p->evaluate(x, out);
    meter.saw_fixed_point(x, out);
  };
  // F itself, when G carries it (FixedPointProblem::residual): metered alike, one evaluation.
  auto residual = [p, &meter](const Eigen::VectorXd& x, Eigen::VectorXd& out) {
    if (!meter.take()) {
      if (meter.late_calls > kLateCallsBeforeStop) throw TimeLimitStop{};
      out.setConstant(p->size(), std::numeric_limits<double>::quiet_NaN());
      return;
    }
    p->residual(x, out);
    meter.saw(out);
  };
  // A Jacobian past the deadline is refused too (NaN).
  const auto late = [&meter, p](Eigen::MatrixXd& jac) {
    if (!meter.late()) return false;
    if (meter.late_calls > kLateCallsBeforeStop) throw TimeLimitStop{};
    jac.setConstant(p->size(), p->size(), std::numeric_limits<double>::quiet_NaN());
    return true;
  };
  // The sparse Jacobian (declared, or detected at the engine's start) goes with the residual
  // form: an engine with a sparse path takes it, as it would from the problem itself.
  const auto with_sparse = [&g](FixedPointProblem<Dynamic> out) {
    return g.sparse_jacobian_state() ? out.with_sparse_jacobian_state(g.sparse_jacobian_state())
                                     : out;
  };
  if (!g.has_jacobian()) {
    auto out = FixedPointProblem<Dynamic>::from_map(map, g.size());
    return g.has_residual() ? with_sparse(out.with_residual(residual)) : out;
  }
  auto jacobian = [p, late](const Eigen::VectorXd& x, Eigen::MatrixXd& jac) {
    if (!late(jac)) p->jacobian(x, jac);
  };
  auto out =
      FixedPointProblem<Dynamic>::with_jacobian(map, jacobian, g.size(), g.jacobian_source());
  if (!g.has_residual()) return out;
  return with_sparse(
      out.with_residual(residual, [p, late](const Eigen::VectorXd& x, Eigen::MatrixXd& jac) {
        if (!late(jac)) p->residual_jacobian(x, jac);
      }));
}

// ∂F for kinsol:newton-klu: the problem's sparse Jacobian (declared or detected at x), its values
// copied in the pattern's row order. std::invalid_argument (an invalid_input row) without one.
KinsolSparseJacobian kinsol_sparse_jacobian(const TestProblem& problem, const Eigen::VectorXd& x) {
  const SparseJacobianSource* source = problem.residual.sparse_jacobian(x);
  if (!source) {
    throw std::invalid_argument("kinsol:newton-klu needs a sparse Jacobian, and F has none (" +
                                problem.residual.sparse_jacobian_note() + ")");
  }
  const SparsityPattern& pattern = *source->pattern;
  KinsolSparseJacobian out;
  out.row_starts.assign(pattern.row_start.begin(), pattern.row_start.end());
  out.columns.assign(pattern.columns.begin(), pattern.columns.end());
  // Through the problem's state: its lock guards the workspace the problem's copies share.
  std::shared_ptr<detail::SparseJacobianState> state = problem.residual.sparse_jacobian_state();
  auto jac = std::make_shared<SparseJacobian>();
  const auto nonzeros = static_cast<Eigen::Index>(out.columns.size());
  out.values = [state, jac, nonzeros](const Eigen::VectorXd& at, const Eigen::VectorXd& f,
                                      double* values) {
    state->evaluate(at, f, *jac);
    if (jac->nonZeros() != nonzeros) {  // the callback makes this KINSOL's Jacobian failure
      throw std::logic_error("the sparse Jacobian's structure is not its pattern's");
    }
    std::copy(jac->valuePtr(), jac->valuePtr() + nonzeros, values);
  };
  return out;
}

// PETSc SNES as its drivers run it with -snes_fd_color: PETSc's coloured differences on F's
// pattern (declared or detected; a dense pattern without one, n ≤ kMaxProblemDimension), its
// defaults otherwise (newtonls: bt line search, GMRES + ILU(0)); converged at ‖F‖₂ ≤ 1e-10 as
// KINSOL at ‖F‖∞ ≤ 1e-10. PETSc takes neither the problem's scaling nor its box.
Outcome run_petsc(const std::string& solver, const TestProblem& problem,
                  const RootProblem<Dynamic>& residual, Eigen::VectorXd& x, long budget) {
  PetscSnesOptions o = PetscSnesSolver::parse_name(solver);
  o.absolute_tolerance = 1e-10;
  o.max_iterations = std::min<long>(budget, std::numeric_limits<int>::max());
  o.max_evaluations = budget;
  PetscPattern pattern;
  if (const SparseJacobianSource* source = problem.residual.sparse_jacobian(x)) {
    pattern.row_starts.assign(source->pattern->row_start.begin(), source->pattern->row_start.end());
    pattern.columns.assign(source->pattern->columns.begin(), source->pattern->columns.end());
  } else if (residual.size() > kMaxProblemDimension) {
    throw std::invalid_argument(
        solver + " needs F's sparse pattern at n = " + std::to_string(residual.size()) + " (" +
        problem.residual.sparse_jacobian_note() + ")");
  }
  const RootProblem<Dynamic>* f = &residual;
  PetscSnesSolver snes(
      static_cast<int>(residual.size()), std::move(o),
      [f](const Eigen::VectorXd& v, Eigen::VectorXd& out) { f->evaluate(v, out); },
      std::move(pattern));
  const PetscSnesResult r = snes.solve(x);
  std::string message = r.error.empty() ? r.reason_text : r.error;
  if (!r.reason_name.empty() && !r.success) {
    message = r.reason_name + (message.empty() ? "" : ": " + message);
  }
  return {r.status(), r.evaluations, r.jacobian_evaluations, message};
}

// MPI's start and PETSc's first use of each of its types (their registration, ~10 ms) happen
// here, untimed: one solve of a 2-unknown system with the name's type and options (its printing
// viewers left out). A failure here is the row's to report.
void warm_up_petsc(const std::string& name) {
  initialize_petsc();
  try {
    PetscSnesOptions o = PetscSnesSolver::parse_name(name);
    std::erase_if(o.options, [](const auto& kv) { return petsc_rules::names_a_viewer(kv.first); });
    PetscSnesSolver snes(2, std::move(o), [](const Eigen::VectorXd& v, Eigen::VectorXd& f) {
      f = v.array() * v.array() - 1.0;
    });
    Eigen::VectorXd x = Eigen::VectorXd::Constant(2, 2.0);
    (void)snes.solve(x);
  } catch (...) {
  }
}

// The references that keep dense n×n matrices: not run above kMaxProblemDimension.
bool dense_reference(const std::string& solver) {
  return solver == "minpack:hybrj" || solver == "gsl:hybridsj" || solver == "gsl:gnewton" ||
         solver == "kinsol:newton";
}

// KINSOL's options and set-up may refuse (std::invalid_argument): the caller makes that row
// invalid_input. `budget` counts every evaluation, the references' checks of their answers
// included.
Outcome run_reference(const std::string& solver, const TestProblem& problem,
                      const RootProblem<Dynamic>& residual, const FixedPointProblem<Dynamic>& g,
                      Eigen::VectorXd& x, long budget) {
  if (dense_reference(solver) && residual.size() > kMaxProblemDimension) {
    throw std::invalid_argument(
        solver + " keeps dense n x n matrices: not run at n = " + std::to_string(residual.size()) +
        ", above " + std::to_string(kMaxProblemDimension) +
        " (kinsol:newton-band, -klu and -spgmr are KINSOL's sparse forms)");
  }
  if (PetscSnesSolver::is_name(solver)) return run_petsc(solver, problem, residual, x, budget);
  ReferenceOptions o;
  o.max_evaluations = budget;
  if (solver == "minpack:hybrj") {
    const ReferenceResult r = solve_minpack_hybrj(residual, x, o);
    return {r.status, r.f_evals, r.j_evals, {}};
  }
  if (solver == "gsl:hybridsj" || solver == "gsl:gnewton") {
    const ReferenceResult r = solve_gsl(solver.substr(4), residual, x, o);
    return {r.status, r.f_evals, r.j_evals, {}};
  }
  KinsolOptions ko;
  ko.strategy = KinsolSolver::strategy(solver).value_or(KinsolStrategy::kNewtonLineSearch);
  ko.tolerance = 1e-10;
  // The problem's scaling, as KINSOL's own drivers give it (MINPACK and GSL take none: hybrj
  // scales its variables itself, as MINPACK's driver runs it).
  ko.u_scale = problem.u_scale;
  ko.f_scale = problem.f_scale;
  // KINSOL counts iterations (each at least one evaluation); max_evaluations bounds the
  // evaluations its line search and the final check add.
  ko.max_iterations = budget;
  ko.max_evaluations = budget;
  // KINSOL's own maximum step, 1000 ‖u₀‖₂, collapses to 1 at u₀ = 0 (Watson's start, a
  // user's zero start): the same rule measured from 1 instead (docs/solvers.md); ‖u₀‖₂ without
  // overflow and the product at most the largest double (a start of 1e308).
  ko.max_newton_step = std::min(std::numeric_limits<double>::max(),
                                1000.0 * std::max(1.0, x.allFinite() ? x.stableNorm() : 1.0));
  const int n = static_cast<int>(residual.size());
  std::unique_ptr<KinsolSolver> k;
  if (ko.strategy == KinsolStrategy::kNewtonLineSearch) {
    ko.linear_solver = KinsolSolver::linear_solver(solver).value_or(KinsolLinearSolver::kDense);
    KinsolSolver::Jacobian dense;
    KinsolSparseJacobian sparse;
    const RootProblem<Dynamic>* f = &residual;
    switch (ko.linear_solver) {
      case KinsolLinearSolver::kDense:  // exact Newton on our Jacobian, as in the small sets
        dense = [f](const Eigen::VectorXd& v, Eigen::MatrixXd& j) { f->jacobian(v, j); };
        break;
      case KinsolLinearSolver::kBand: {  // the widths of F's pattern; the full band without one
        const SparseJacobianSource* source = problem.residual.sparse_jacobian(x);
        const PatternBandwidths band =
            source ? pattern_bandwidths(*source->pattern) : PatternBandwidths{n - 1, n - 1};
        ko.lower_bandwidth = band.lower;
        ko.upper_bandwidth = band.upper;
        ko.max_setup_calls = 0;  // KINSOL's default: modified Newton
        break;
      }
      case KinsolLinearSolver::kKlu:
        sparse = kinsol_sparse_jacobian(problem, x);
        ko.max_setup_calls = 0;
        break;
      case KinsolLinearSolver::kSpgmr:
        ko.max_setup_calls = 0;
        break;
    }
    k = std::make_unique<KinsolSolver>(
        n, ko, [f](const Eigen::VectorXd& v, Eigen::VectorXd& out) { f->evaluate(v, out); },
        std::move(dense), std::move(sparse));
  } else {
    const FixedPointProblem<Dynamic>* gp = &g;
    k = std::make_unique<KinsolSolver>(
        n, ko, [gp](const Eigen::VectorXd& v, Eigen::VectorXd& out) { gp->evaluate(v, out); });
  }
  const KinsolResult r = k->solve(x);
  return {r.status(), r.evaluations, r.jacobian_evaluations, r.reason};
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
  for (const char* more : {"kinsol:fp", "kinsol:fp-aa2", "kinsol:newton-band", "kinsol:newton-klu",
                           "kinsol:newton-spgmr"}) {
    s.emplace_back(more);
  }
  if (petsc_available()) {
    for (const std::string& name : PetscSnesSolver::names()) s.push_back(name);
  }
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
  if (!(options.time_limit_s > 0.0)) {
    throw InvalidInput("the time limit per solve must be > 0 seconds (+inf: none), got " +
                       std::to_string(options.time_limit_s));
  }
  auto& registry = EngineRegistry<Dynamic>::global();
  SolverOptions base;
  base.stop.step_tolerance = 1e-12;
  base.stop.residual_tolerance = 1e-10;
  // Validate every name and start label before running anything.
  for (const std::string& s : solvers) {
    if (PetscSnesSolver::is_name(s)) {
      (void)PetscSnesSolver::parse_name(s);  // its syntax now; PETSc's own refusals in its row
      if (petsc_available()) warm_up_petsc(s);
      continue;
    }
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
  Meter meter;
  for (const TestProblem& p : problems) {
    const Index n = p.size();
    // K (n + 1), saturated (K ≤ 1e6 and n ≤ kMaxProblemDimension keep it far from overflow).
    const long budget = n + 1 > std::numeric_limits<long>::max() / options.evaluations_per_dimension
                            ? std::numeric_limits<long>::max()
                            : options.evaluations_per_dimension * static_cast<long>(n + 1);
    const FixedPointProblem<Dynamic> g =
        p.fixed_point ? *p.fixed_point : to_fixed_point<Dynamic>(p.residual);
    const RootProblem<Dynamic> judge_f = guarded(p.residual, nullptr);  // the suite's own look
    const RootProblem<Dynamic> safe_f = guarded(p.residual, &meter);
    const FixedPointProblem<Dynamic> safe_g = guarded(g, &meter);
    const FixedPointProblem<Dynamic> engine_g = metered(g, meter);
    meter.f_scale = &p.f_scale;
    // The pattern of a with_autodiff F is detected once per problem (at the first start), here
    // and untimed: the first solver of the list would otherwise be timed with it. What it
    // throws, an engine meets again (and its row says so).
    try {
      (void)p.residual.sparse_jacobian(p.starts.front().x);
    } catch (...) {
    }
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
        meter.reset(budget, options.time_limit_s);
        // Whatever a solver's options, set-up or run throw, the row says so and the suite goes
        // on: invalid_input (options or set-up refused, the problem's box refused),
        // out_of_memory (std::bad_alloc), engine_threw (anything else, `throw 42` included).
        bool setting_up = true;
        // A solve ended by an exception (the time limit's, an engine's) has no mean over repeated
        // calls: its row gives the wall time of that one attempt, not 0. So does a row the time
        // limit ended: the row is the last of the timed calls, and a mean with earlier calls that
        // ended in time could show less than the limit it was stopped at.
        auto attempt_started = std::chrono::steady_clock::now();
        auto attempt_ns = [&attempt_started] {
          return std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() -
                                                          attempt_started)
              .count();
        };
        try {
          if (is_reference(s)) {
            row.ns = mean_ns_per_call(
                [&] {
                  attempt_started = std::chrono::steady_clock::now();
                  x = start.x;
                  meter.reset(budget, options.time_limit_s);
                  outcome = run_reference(s, p, safe_f, safe_g, x, budget);
                },
                kTimingNs, 1, kMaxTimedCalls);
          } else {
            SolverOptions o = base;
            o.stop.max_evaluations = static_cast<int>(std::min<long>(budget, 1L << 30));
            const std::string problem_start = p.name + "/" + start.label;
            if (options.monitor) {
              o.iteration_callback = [&options, &s, &problem_start](const IterationRecord& r) {
                options.monitor(s, problem_start, r);
                return IterationDecision::kContinue;
              };
            }
            auto engine = registry.create(s, o);
            // The problem's box reaches the engines that take bounds (its strict sides those
            // that take them; Ceres and NLopt the closed box inside it); the others run
            // unbounded and are judged alike (outside_bounds). levenberg-marquardt:geodesic=1
            // and a user's engine may refuse it: invalid_input.
            if ((p.lower.size() > 0 || p.upper.size() > 0) && engine->accepts_bounds()) {
              engine->set_bounds(engine->accepts_strict_bounds() ? p.bounds() : closed_inside(p));
            }
            // The problem's scaling likewise (the Newton-type engines; docs/solvers.md).
            if ((p.u_scale.size() > 0 || p.f_scale.size() > 0) && engine->accepts_scaling()) {
              engine->set_scaling({p.u_scale, p.f_scale});
            }
            setting_up = false;
            row.ns = mean_ns_per_call(
                [&] {
                  attempt_started = std::chrono::steady_clock::now();
                  x = start.x;
                  meter.reset(budget, options.time_limit_s);
                  const Summary sum = solve_or_report(*engine, engine_g, x);
                  // The metered count: every evaluation of G the engine made.
                  outcome = {std::string(to_string(sum.status)), meter.count,
                             sum.jacobian_evaluations, sum.message};
                },
                kTimingNs, 1, options.monitor ? 1 : kMaxTimedCalls);
          }
          if (meter.timed_out) row.ns = attempt_ns();
        } catch (const TimeLimitStop&) {
          row.ns = attempt_ns();
          outcome = {"time_limit", meter.count, 0, ""};
          x.resize(0);  // unwound: no answer
        } catch (const std::bad_alloc&) {
          row.ns = attempt_ns();
          outcome = {"out_of_memory", meter.count, 0, "std::bad_alloc: not enough memory"};
          x.resize(0);
        } catch (...) {
          row.ns = attempt_ns();
          const bool refused_input = (setting_up || is_reference(s)) && [] {
            try {
              throw;
            } catch (const std::invalid_argument&) {  // InvalidInput is one
              return true;
            } catch (...) {
              return false;
            }
          }();
          outcome = {refused_input ? "invalid_input" : "engine_threw", meter.count, 0,
                     current_exception_text()};
          x.resize(0);  // no answer
        }
        row.message = printable(outcome.message);
        row.residual = row.scaled_residual = std::numeric_limits<double>::infinity();
        if (x.size() == n && x.allFinite()) {
          Eigen::VectorXd f(n);
          judge_f.evaluate(x, f);
          if (f.allFinite()) {
            row.residual = f.norm();
            row.scaled_residual = p.f_scale.size() ? p.scaled_norm(f) : row.residual;
          }
        }
        if (x.size() == n) row.x = x;
        row.status = outcome.status;
        const bool in_box = x.size() == n && !p.first_outside_bounds(x);
        // A point that is not finite keeps the solver's own account (non_finite, ...): it is no
        // point outside the box.
        if (x.size() == n && x.allFinite() && !in_box) row.status = "outside_bounds";
        // An evaluation asked for beyond the budget was refused: whatever the point, not solved.
        if (meter.timed_out) {
          row.status = "time_limit";
          std::ostringstream why;
          why << "asked for an evaluation after the time limit of " << options.time_limit_s
              << " s (refused"
              << (meter.late_calls > kLateCallsBeforeStop
                      ? "; asked ten more times, stopped by an exception)"
                      : ")");
          // What the engine said of the NaN it was given is beside the point.
          row.message = why.str();
        } else if (meter.refused) {
          row.status = "max_evaluations";
          if (row.message.empty()) {
            row.message = "asked for an evaluation beyond the budget of " + std::to_string(budget) +
                          " (refused)";
          }
        }
        row.solved = x.size() == n && in_box && !meter.refused && !meter.timed_out &&
                     row.scaled_residual <= threshold;
        row.error =
            x.size() == n ? distance_to_solutions(p, x) : std::numeric_limits<double>::infinity();
        row.f_evals = outcome.f_evals;
        row.evals_past_progress = meter.past_progress();
        row.j_evals = outcome.j_evals;
        rows.push_back(std::move(row));
      }
      if (options.progress) options.progress(++done, total);
    }
  }
  return rows;
}

}  // namespace nlobs::reference
