// Solves the modified-Chua window problem through the installed headers and libraries (the
// grouped path of the window family: docs/observers.md, "Header layout").
#include <cstdio>
#include <nlobs/models/modified_chua.hpp>
#include <nlobs/observers/window/window_problems.hpp>
#include <nlobs/solvers/solvers.hpp>

int main() {
  const auto model = nlobs::paper_modified_chua();
  nlobs::OutputWindow<nlobs::Discretized<nlobs::ModifiedChua>> window(model, 3);
  Eigen::Vector3d x(1.0, 2.1428, -0.1648);
  const Eigen::Vector3d truth = x;
  for (long k = 0; k < 3; ++k) {
    window.push(k, model.h(x), Eigen::VectorXd(0));
    x = model.f(x, {}, k);
  }
  const auto problem = nlobs::square_window_problem(window);
  nlobs::SteffensenEngine<3> engine;
  nlobs::Vector<3> w(5.0, 10.0, -5.0);
  const nlobs::Summary s = engine.solve(problem, w);
  std::printf("%s\n", s.brief_report().c_str());
  return s.converged() && (w - truth).lpNorm<Eigen::Infinity>() < 1e-6 ? 0 : 1;
}
