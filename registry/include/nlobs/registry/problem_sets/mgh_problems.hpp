#pragma once
// The fourteen square nonlinear systems of MINPACK's test driver (Moré, Garbow & Hillstrom,
// MINPACK-1 `vecfcn`, standard starting points from `initpt`), in the dimensions the issue
// lists: 20 (problem, n) cases. Functions are generic in the scalar, so Jacobians come from
// forward-mode AD (Eigen AutoDiffScalar at run-time sizes).
#include <Eigen/Core>
#include <string>
#include <vector>

#include "nlobs/registry/problem_sets.hpp"
#include "nlobs/solvers/problem.hpp"

namespace nlobs::reference {

struct MghCase {
  std::string name;  // e.g. "chebyquad"
  int number = 0;    // MINPACK's problem number, 1..14
  int n = 0;
  RootProblem<Dynamic> problem;  // F with an AD Jacobian
  // MINPACK's initpt: the standard start times `scale` (Watson: all components = scale when
  // scale != 1, since its standard start is 0).
  Eigen::VectorXd start(double scale) const;
};

// In MINPACK's order: Rosenbrock, Powell singular, Powell badly scaled, Wood, helical valley,
// Watson (6, 9), Chebyquad (5..9), Brown almost-linear, discrete boundary value, discrete
// integral equation, trigonometric, variably dimensioned, Broyden tridiagonal, Broyden
// banded (n = 10 each).
std::vector<MghCase> mgh_cases();

// One case by MINPACK number and dimension (throws std::invalid_argument if not in the list).
MghCase mgh_case(int number, int n);

}  // namespace nlobs::reference

namespace nlobs {
// The built-in set "mgh": the cases above in MINPACK's order, named as mgh_cases() names them
// (Watson and Chebyquad once per size: mgh/chebyquad:n=5), each from MINPACK's standard start
// scaled by 1, 10 and 100 (starts "x1", "x10", "x100"); known solutions where they are exact
// (Rosenbrock, Powell singular, Wood, helical valley, Brown almost-linear, variably
// dimensioned).
ProblemSetEntry mgh_problem_set();
}  // namespace nlobs
