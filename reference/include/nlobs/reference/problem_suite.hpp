#pragma once
// `nlobs suite SET` and `nlobs solve SET/NAME`: every listed solver — an engine of the registry
// (any spec, a user's engine too, the reference engines of reference_engines.hpp: KINSOL,
// MINPACK, GSL, PETSc) — on every (problem, start) of a
// problem set, judged the same way for all: solved when the returned point is finite, inside
// the problem's bounds and ‖D_f F(x)‖₂ ≤ the threshold (1e-8 unless the set or the caller says
// otherwise; D_f the problem's f_scale, the identity without one), within the budget and the
// time limit.
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "nlobs/registry/problem_sets.hpp"

namespace nlobs {
struct IterationRecord;  // nlobs/solvers/engine.hpp
}  // namespace nlobs

namespace nlobs::reference {

struct SuiteRow {
  std::string set;  // the problem set's name
  std::string problem;
  int n = 0;
  std::string start;  // the start's label ("x1", "x10", ...)
  double start_scale = 1.0;
  std::string solver;
  bool solved = false;
  double residual = 0.0;  // ‖F(x)‖₂ at the returned x (inf if not finite)
  // min over the known solutions x* of ‖x − x*‖∞ (NaN when the problem lists none).
  double error = 0.0;
  long f_evals = 0;
  long j_evals = 0;
  double ns = 0.0;  // wall time per solve
  // The solver's own account; `outside_bounds` for a point outside the box; `max_evaluations`
  // for a solver that asked for an evaluation beyond its budget (refused; never solved);
  // `time_limit` for one whose evaluation past SuiteOptions::time_limit_s was refused (never
  // solved);
  // `invalid_input` (a solver's options or set-up refused, the problem's box refused),
  // `engine_threw` (any exception, `throw 42` included) or `out_of_memory` (std::bad_alloc),
  // each a row with no answer (residual and error inf).
  std::string status;
  // Why, when the solver said (its Summary::message, KINSOL's reason) or threw (the exception's
  // text): printable (nlobs::printable), at most ~200 bytes; empty otherwise.
  std::string message;
  // ‖D_f F(x)‖₂, what `solved` is judged on: residual itself when the problem has no f_scale.
  double scaled_residual = 0.0;
  // The returned point as the solver returned it (NaN, ±inf, 1e308 included), of size n; empty
  // for a row without an answer (invalid_input, engine_threw, out_of_memory, a time limit that
  // had to stop the engine by an exception).
  Eigen::VectorXd x{};
  // F evaluations made after the last one at which ‖D_f F‖₂ fell below 0.999 × the lowest
  // before it, counted at the evaluated points (difference points and line-search trials too):
  // what a solver spent once it had stopped making progress (all of f_evals if it never did).
  long evals_past_progress = 0;
};

struct SuiteOptions {
  // ‖F‖₂ at or below this at the returned point counts as solved; NaN: the set's own default
  // (ProblemSetEntry::solved_threshold). Otherwise finite and > 0.
  double solved_threshold = std::numeric_limits<double>::quiet_NaN();
  // Every solver gets the same budget of F evaluations: evaluations_per_dimension (n + 1), at
  // least 1. Enforced for every solver: our engines get it as StopCriteria::max_evaluations, the
  // references as their libraries' own limits (MINPACK's maxfev, GSL's loop, KINSOL's
  // iterations) and every evaluation is counted at the callback: one beyond the budget is
  // refused (NaN, before F is called), the solver stops and its row is max_evaluations, not
  // solved. f_evals never exceeds the budget.
  long evaluations_per_dimension = 1000;
  // Wall time each solve may take, in seconds (+inf: no limit; otherwise > 0). Checked at every
  // evaluation of F, G or a Jacobian: past the limit the evaluation is refused (NaN, the problem
  // not called), the solver stops as at its budget, and the row is `time_limit`, not solved. An
  // engine of ours (a user's among them) that asks again ten times after a refusal is stopped by
  // an exception (row without an answer). A single slow evaluation, or a solver computing long
  // between two, overruns the limit by that long.
  double time_limit_s = std::numeric_limits<double>::infinity();
  // Only the starts with these labels (empty: all); a label no problem has is an error.
  std::vector<std::string> starts{};
  // Called after each (problem, start) pair, e.g. for a progress line.
  std::function<void(int done, int total)> progress{};
  // Called after each iteration of each of our engines' solves (SolverOptions::
  // iteration_callback; the references have their own monitors) with the solver's spec and the
  // row's "problem/start": `nlobs suite --monitor`. A monitored solve is run once, not repeated
  // for its timing.
  std::function<void(const std::string& solver, const std::string& problem_start,
                     const IterationRecord& record)>
      monitor{};
};

// Our engines (registry specs) in the default order, then the default references.
std::vector<std::string> default_suite_solvers();
// The references run by default: minpack:hybrj, kinsol:newton, gsl:hybridsj, gsl:gnewton.
std::vector<std::string> reference_suite_solvers();
// Every reference name accepted: the default ones, KINSOL's fixed-point strategies kinsol:fp and
// kinsol:fp-aa2 (on G: the problem's own, or x + F(x)), and its Newton on sparse linear solvers,
// each with KINSOL's default modified Newton (a Jacobian at least every 10 iterations):
// kinsol:newton-band (its difference-quotient band Jacobian, the widths of F's pattern),
// kinsol:newton-klu (F's sparse Jacobian, declared or detected; invalid_input without one) and
// kinsol:newton-spgmr (difference-quotient J·v, no preconditioner). The dense references
// (minpack:hybrj, gsl:*, kinsol:newton) are not run above kMaxProblemDimension unknowns: their
// rows are invalid_input, saying why. With PETSc (petsc_available()): PETSc's SNES as
// petsc:newtonls, newtontr, ngmres, anderson, qn and nrichardson (petsc_solver.hpp: PETSc's
// coloured differences on F's pattern); run_suite also takes any petsc:TYPE[:-key=value...].
std::vector<std::string> all_reference_solvers();

// The threshold `options` give for `set` (its own when options leave it NaN); InvalidInput for
// a value that is not finite and > 0.
double suite_threshold(const ProblemSetEntry& set, const SuiteOptions& options);

// The (problem, start) pairs run_suite runs: the starts options.starts selects.
int count_suite_pairs(const std::vector<TestProblem>& problems, const SuiteOptions& options);

// Throws std::invalid_argument for an unknown solver (listing the valid names, references
// included) or an unknown start label, before anything runs.
std::vector<SuiteRow> run_suite(const ProblemSetEntry& set,
                                const std::vector<TestProblem>& problems,
                                const std::vector<std::string>& solvers,
                                const SuiteOptions& options = {});

// Splits a --solvers/--engines list on commas, keeping "key=value" items with the spec
// before them: "anderson:m=3,damping=0.5,newton" -> {"anderson:m=3,damping=0.5", "newton"}.
std::vector<std::string> split_spec_list(const std::string& list);

}  // namespace nlobs::reference
