// A user's file that names an engine by string: it includes the registry only, so it pays for
// parsing, not for compiling the engines (scripts/compile-cost reports its time).
#include <cmath>
#include <cstdio>
#include <nlobs/solvers/engine_registry.hpp>

int main() {
  // G(x) = 0.5 cos(x) + c componentwise: a contraction with one fixed point.
  const auto problem =
      nlobs::FixedPointProblem<3>::from_map([](const nlobs::Vector<3>& x, nlobs::Vector<3>& g) {
        for (int i = 0; i < 3; ++i) g[i] = 0.5 * std::cos(x[i]) + 0.1 * i;
      });
  int failures = 0;
  for (const char* spec : {"newton", "anderson:m=2", "ceres"}) {
    auto engine = nlobs::EngineRegistry<3>::global().create(spec);
    nlobs::Vector<3> x = nlobs::Vector<3>::Zero();
    const nlobs::Summary s = engine->solve(problem, x);
    std::printf("%s: %s\n", spec, s.brief_report().c_str());
    for (int i = 0; i < 3; ++i) {
      if (!(std::abs(0.5 * std::cos(x[i]) + 0.1 * i - x[i]) < 1e-6)) ++failures;
    }
  }
  return failures == 0 ? 0 : 1;
}
