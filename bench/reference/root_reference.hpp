#pragma once
// Established square-system solvers run on the same RootProblem as our engines, with the same
// analytic (AD) Jacobian: MINPACK hybrj, GSL hybridsj and gnewton. (KINSOL: kinsol_solver.hpp.)
#include <Eigen/Core>
#include <string>

#include "nlobs/solvers/problem.hpp"

namespace nlobs::reference {

struct ReferenceResult {
  std::string status;  // "converged" or the solver's own reason
  long f_evals = 0;
  long j_evals = 0;
};

struct ReferenceOptions {
  double tolerance = 1e-10;  // hybrj: xtol; GSL: residual test sum|F_i| < tol and step test
  long max_evaluations = 10000;
};

// MINPACK hybrj (Powell hybrid method, user Jacobian), through cminpack.
ReferenceResult solve_minpack_hybrj(const RootProblem<Dynamic>& problem, Eigen::VectorXd& x,
                                    const ReferenceOptions& options);

// GSL gsl_multiroot_fdfsolver_hybridsj (scaled hybrid) or _gnewton (globally convergent
// Newton). `method` is "hybridsj" or "gnewton".
ReferenceResult solve_gsl(const std::string& method, const RootProblem<Dynamic>& problem,
                          Eigen::VectorXd& x, const ReferenceOptions& options);

}  // namespace nlobs::reference
