#pragma once
// The established solvers nlobs is compared with, as engines of the registry — the one call
// shape, `engine.solve(problem, x)` → Summary, wherever an engine is named: `nlobs suite` and
// `nlobs solve`, a window estimator's "engine", a user's program.
//
//   kinsol:fp | fp-aa2 | newton | newton-band | newton-klu | newton-spgmr   (kinsol_solver.hpp)
//   minpack:hybrj                                       (root_reference.hpp, cminpack)
//   gsl:hybridsj | gnewton                              (root_reference.hpp)
//   petsc:TYPE[:-key=value...]   when nlobs was built with PETSc (petsc_solver.hpp)
//
// Each runs as its library's drivers configure it (what the suite compares): its tolerances are
// its own spec keys with those drivers' defaults, not StopCriteria's. Of SolverOptions a
// reference engine takes max_evaluations (the budget, at least 2, enforced at the callback:
// f_evals never exceeds it) for its run, and residual_tolerance and acceptance_tolerance only
// as every engine does, for Summary::usable(); the common keys it does not take are refused in
// a spec.
// Summary::library_status holds the library's own account ("xtol_too_small",
// "kin_linesearch_nonconv"), Summary::status the nearest Status. F is the problem's residual
// form (FixedPointProblem::residual, else G(x) − x) with its Jacobian (∂F, else ∂G − I); the
// fixed-point strategies iterate G. An exception F throws is kept while the C library stops (it
// sees a value that is not finite: nothing unwinds through C) and rethrown from solve(). The
// dense ones (minpack, gsl, kinsol:newton) refuse n above kMaxProblemDimension (InvalidInput).
#include <string_view>

#include "nlobs/solvers/engine_registry.hpp"

namespace nlobs::reference {

// Adds kinsol, minpack, gsl and, when nlobs was built with PETSc (petsc_available()), petsc to
// `registry`, skipping the names it already has.
void add_reference_engines(EngineRegistry<Dynamic>& registry);

// add_reference_engines(EngineRegistry<Dynamic>::global()) once per process (thread-safe; later
// calls return at once). Every fixed size reaches them through its Dynamic fallback. The nlobs
// CLI and run_suite() call it; a program that wants the reference engines by name calls it.
void register_reference_engines();

// Whether `spec` names one of the engines add_reference_engines adds (kinsol, minpack, gsl,
// petsc), by the name before its ':'.
bool is_reference_engine(std::string_view spec);

}  // namespace nlobs::reference
