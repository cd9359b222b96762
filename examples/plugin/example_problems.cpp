// A two-problem set, `example`: `nlobs suite example` runs bad-broyden beside the built-in engines,
// KINSOL, MINPACK and GSL on every (problem, start).
#include <cmath>

#include "example_plugin.hpp"

namespace example {
namespace {

// x1² + x2² = 2 and x1 = x2 inside [0, 3]²: the root (1, 1); (−1, −1) lies outside the box.
nlobs::TestProblem circle_and_line() {
  nlobs::TestProblem p = nlobs::root_test_problem(
      "circle-line", 2,
      [](const auto& x, auto& f) {
        f[0] = x[0] * x[0] + x[1] * x[1] - 2.0;
        f[1] = x[0] - x[1];
      },
      {{"near", Eigen::Vector2d(2.0, 0.5), 1.0}, {"far", Eigen::Vector2d(3.0, 3.0), 1.0}});
  p.lower = Eigen::Vector2d::Zero();
  p.upper = Eigen::Vector2d::Constant(3.0);
  p.solutions = {Eigen::Vector2d::Ones()};
  p.description = "x1^2 + x2^2 = 2, x1 = x2 in [0, 3]^2";
  return p;
}

// The Bratu problem u'' + λ eᵘ = 0 on (0, 1), u(0) = u(1) = 0, by central differences on n
// interior points (λ = 1, the lower branch; Bratu 1914, Kelley 1995 §5.7).
nlobs::TestProblem bratu(int n) {
  nlobs::TestProblem p = nlobs::root_test_problem(
      "bratu-1d", n,
      [n](const auto& u, auto& f) {
        const double h = 1.0 / (n + 1);
        for (int i = 0; i < n; ++i) {
          using T = std::decay_t<decltype(u[0])>;
          const T left = i > 0 ? u[i - 1] : T(0.0);
          const T right = i + 1 < n ? u[i + 1] : T(0.0);
          using std::exp;
          f[i] = (left - 2.0 * u[i] + right) / (h * h) + exp(u[i]);
        }
      },
      {{"zero", Eigen::VectorXd::Zero(n), 1.0}, {"ten", Eigen::VectorXd::Constant(n, 10.0), 10.0}});
  p.description = "u'' + e^u = 0, u(0) = u(1) = 0, central differences";
  return p;
}

}  // namespace

void add_example_problems(nlobs::PluginRegistrar& registrar) {
  registrar.add_problem_set(
      {.name = "example", .description = "the example plugin's two problems", .problems = [] {
         return std::vector<nlobs::TestProblem>{circle_and_line(), bratu(8)};
       }});
}

}  // namespace example
