// The README's example: a root problem, its fixed-point form, two engines, one summary format.
#include <cstdio>
#include <nlobs/solvers/solvers.hpp>

int main() {
  // F(x) = [x1² + x2² − 4, x1 − x2]: written once, generic in the scalar, so AD gives ∂F.
  auto f = [](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    Eigen::Matrix<T, 2, 1> r;
    r << x[0] * x[0] + x[1] * x[1] - 4.0, x[0] - x[1];
    return r;
  };
  const auto root = nlobs::RootProblem<2>::with_autodiff(f);
  const auto problem = nlobs::to_fixed_point<2>(root, -0.2);  // G(x) = x − 0.2 F(x)

  nlobs::SolverOptions options;
  options.stop.step_tolerance = 1e-12;
  nlobs::AndersonEngine<2> anderson({.depth = 2}, options);
  nlobs::NewtonEngine<2> newton({.line_search = true}, options);

  for (nlobs::Engine<2>* engine :
       {static_cast<nlobs::Engine<2>*>(&anderson), static_cast<nlobs::Engine<2>*>(&newton)}) {
    nlobs::Vector<2> x(1.0, 2.0);
    const nlobs::Summary summary = engine->solve(problem, x);
    std::printf("%s\n  x = (%.15f, %.15f)\n", summary.brief_report().c_str(), x[0], x[1]);
    if (!summary.converged()) return 1;
  }
  return 0;
}
