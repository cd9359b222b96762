#include "nlobs/registry/problem_sets/chua_window_set.hpp"

#include <memory>

namespace nlobs {

ProblemSetEntry chua_window_problem_set() {
  ProblemSetEntry set;
  set.name = "chua-window";
  set.description =
      "the modified-Chua square window of [MGFF23]: x = G(x) = x + (Y - H(x)), n = 3, from the "
      "paper's guess [5, 10, -5] (x1) and ten times it (x10)";
  set.problems = [] {
    // Shared by both maps: G(w) refers to the window inside the case.
    const auto c = std::make_shared<const reference::ChuaWindowCase>();
    auto g = [c](const Eigen::VectorXd& x, Eigen::VectorXd& out) {
      Vector<3> x3 = x, g3;
      c->problem.evaluate(x3, g3);
      out = g3;
    };
    auto dg = [c](const Eigen::VectorXd& x, Eigen::MatrixXd& jac) {
      Matrix<3, 3> j3;
      c->problem.jacobian(Vector<3>(x), j3);
      jac = j3;
    };
    auto f = [g](const Eigen::VectorXd& x, Eigen::VectorXd& out) mutable {
      g(x, out);
      out -= x;
    };
    auto df = [dg](const Eigen::VectorXd& x, Eigen::MatrixXd& jac) mutable {
      dg(x, jac);
      jac -= Eigen::MatrixXd::Identity(3, 3);
    };
    TestProblem p{
        .name = "window",
        .residual = RootProblem<Dynamic>::with_jacobian(f, df, 3, 3, JacobianSource::kAutoDiff),
        .fixed_point =
            FixedPointProblem<Dynamic>::with_jacobian(g, dg, 3, JacobianSource::kAutoDiff),
        .starts = {{"x1", c->initial_guess, 1.0}, {"x10", 10.0 * c->initial_guess, 10.0}},
        .solutions = {c->true_state},
        .description = "G(w) = w + (Y - H(w)) over the first three outputs"};
    std::vector<TestProblem> problems;
    problems.push_back(std::move(p));
    return problems;
  };
  return set;
}

}  // namespace nlobs
