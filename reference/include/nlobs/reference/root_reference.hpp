#pragma once
// Established square-system solvers run on the same RootProblem as our engines, with the same
// analytic (AD) Jacobian: MINPACK hybrj, GSL hybridsj and gnewton. (KINSOL: kinsol_solver.hpp.)
#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

#include "nlobs/solvers/problem.hpp"

namespace nlobs::reference {

struct ReferenceResult {
  std::string status;  // "converged" or the solver's own reason
  long f_evals = 0;
  long j_evals = 0;
  long iterations = 0;  // GSL: the calls of its iterate(); MINPACK's hybrj does not say (0)
  // ‖F‖∞ at the returned x, from check_answer's evaluation: inf where F is not finite there; NaN
  // when x itself is not finite (no evaluation).
  double residual = std::numeric_limits<double>::quiet_NaN();
};

struct ReferenceOptions {
  double tolerance = 1e-10;  // GSL: residual test sum|F_i| < tol and step test
  // hybrj's xtol: √ε, what MINPACK's test driver gives hybrj1 (tests/data/minpack/README.md).
  double minpack_xtol = std::sqrt(std::numeric_limits<double>::epsilon());
  // Every evaluation of F counts, check_answer's included: the library gets max_evaluations − 1
  // of them (MINPACK's maxfev, GSL's loop), the check the last one. An evaluation beyond that is
  // refused before F is called — the library is told to stop (MINPACK: iflag < 0; GSL:
  // GSL_EBADFUNC) — and the status is "max_evaluations": f_evals ≤ max_evaluations always.
  // At least 2.
  long max_evaluations = 10000;
  // A solver's "converged" stands only for a finite point with ‖F‖∞ ≤ residual_tolerance
  // (checked by one more evaluation, counted): hybrj's xtol test and GSL's step test stop on
  // the step alone.
  double residual_tolerance = 1e-8;
};

// The check above: evaluates F at the returned x (counted in f_evals) and replaces a
// "converged" that does not stand by "non_finite" or "residual_above_tolerance".
// `result.f_evals` must be at most options.max_evaluations − 1.
inline void check_answer(const RootProblem<Dynamic>& problem, const Eigen::VectorXd& x,
                         const ReferenceOptions& options, ReferenceResult& result) {
  if (!x.allFinite()) {
    if (result.status == "converged") result.status = "non_finite";
    return;
  }
  Eigen::VectorXd f(problem.residual_size());
  problem.evaluate(x, f);
  ++result.f_evals;
  result.residual =
      f.allFinite() ? f.lpNorm<Eigen::Infinity>() : std::numeric_limits<double>::infinity();
  if (result.status != "converged") return;
  if (!f.allFinite()) {
    result.status = "non_finite";
  } else if (!(f.lpNorm<Eigen::Infinity>() <= options.residual_tolerance)) {
    result.status = "residual_above_tolerance";
  }
}

// MINPACK hybrj (Powell hybrid method, user Jacobian), through cminpack, configured as hybrj1
// (MINPACK's easy-to-use driver, which its published test driver runs): mode 2 with diag = 1
// (no internal rescaling), factor = 100, xtol = options.minpack_xtol (√ε); maxfev is
// options.max_evaluations − 1 (hybrj1: 100 (n + 1); the suite's budget otherwise). f_evals counts
// hybrj's own evaluations plus check_answer's one. Statuses: converged, max_evaluations,
// xtol_too_small, not_making_progress_jacobian, not_making_progress (hybrj's info 1..5),
// non_finite (F or ∂F not finite), improper_input, residual_above_tolerance.
ReferenceResult solve_minpack_hybrj(const RootProblem<Dynamic>& problem, Eigen::VectorXd& x,
                                    const ReferenceOptions& options);

// GSL gsl_multiroot_fdfsolver_hybridsj (scaled hybrid) or _gnewton (globally convergent
// Newton). `method` is "hybridsj" or "gnewton". Statuses as MINPACK's: converged,
// max_evaluations, non_finite (GSL_EBADFUNC), singular_jacobian (GSL_EDOM: gnewton's LU solve of
// a singular Jacobian), not_making_progress (GSL_ENOPROG), not_making_progress_jacobian
// (GSL_ENOPROGJ), residual_above_tolerance; another GSL error as gsl_error_<code>.
ReferenceResult solve_gsl(const std::string& method, const RootProblem<Dynamic>& problem,
                          Eigen::VectorXd& x, const ReferenceOptions& options);

}  // namespace nlobs::reference
