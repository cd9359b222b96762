// Solves the modified-Chua window problem through the installed headers and libraries.
#include <cstdio>
#include <nlobs/models/modified_chua.hpp>
#include <nlobs/observers/window_map.hpp>
#include <nlobs/solvers/solvers.hpp>

int main() {
  const nlobs::WindowMap<nlobs::ModifiedChua, 3> map{nlobs::ModifiedChua{}};
  const nlobs::Vector<3> truth(1.0, 2.1428, -0.1648);
  const auto problem = nlobs::window_fixed_point_problem(map, map(truth));
  nlobs::SteffensenEngine<3> engine;
  nlobs::Vector<3> x(5.0, 10.0, -5.0);
  const nlobs::Summary s = engine.solve(problem, x);
  std::printf("%s\n", s.brief_report().c_str());
  return s.converged() && (x - truth).lpNorm<Eigen::Infinity>() < 1e-6 ? 0 : 1;
}
