#pragma once
// Hands an nlobs FixedPointProblem to KINSOL in the form each strategy expects: G itself for
// the fixed-point strategies, F = G − x and ∂F = ∂G − I (the problem's own Jacobian) for Newton.
#include <memory>

#include "nlobs/reference/kinsol_solver.hpp"
#include "nlobs/solvers/problem.hpp"

namespace nlobs::reference {

// `problem` must outlive the solver.
template <int N>
std::unique_ptr<KinsolSolver> make_kinsol_solver(const FixedPointProblem<N>& problem,
                                                 KinsolOptions options) {
  const int n = static_cast<int>(problem.size());
  KinsolSolver::Function function;
  KinsolSolver::Jacobian jacobian;
  if (options.strategy == KinsolStrategy::kNewtonLineSearch) {
    function = [&problem](const Eigen::VectorXd& x, Eigen::VectorXd& f) {
      Vector<N> g(x.size());
      problem.evaluate(x, g);
      f = g - x;
    };
    if (problem.has_jacobian()) {
      jacobian = [&problem](const Eigen::VectorXd& x, Eigen::MatrixXd& j) {
        Matrix<N, N> dg(x.size(), x.size());
        problem.jacobian(x, dg);
        j = dg;
        j.diagonal().array() -= 1.0;
      };
    }
  } else {
    function = [&problem](const Eigen::VectorXd& x, Eigen::VectorXd& g) {
      Vector<N> gx(x.size());
      problem.evaluate(x, gx);
      g = gx;
    };
  }
  return std::make_unique<KinsolSolver>(n, options, std::move(function), std::move(jacobian));
}

}  // namespace nlobs::reference
