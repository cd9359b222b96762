// A user's own benchmark through the installed nlobs::reference component: their problem set,
// registered in their program, run with a built-in engine beside KINSOL, MINPACK and GSL.
#include <cstdio>
#include <nlobs/reference/problem_suite.hpp>
#include <nlobs/registry/plugin.hpp>

int main() {
  nlobs::register_extensions(
      [](nlobs::PluginRegistrar& r) {
        r.add_problem_set(
            {.name = "consumer-set", .description = "x^3 = 8 and x = cos x", .problems = [] {
               return std::vector<nlobs::TestProblem>{
                   nlobs::root_test_problem(
                       "cube", 1, [](const auto& x, auto& f) { f[0] = x[0] * x[0] * x[0] - 8.0; },
                       {{"one", Eigen::VectorXd::Constant(1, 1.0)}}),
                   nlobs::fixed_point_test_problem("cosine", 1,
                                                   [](const auto& x, auto& g) {
                                                     using std::cos;
                                                     g[0] = cos(x[0]);
                                                   },
                                                   {{"zero", Eigen::VectorXd::Zero(1)}})};
             }});
      },
      "consumer");
  const auto selection = nlobs::select_problems("consumer-set", nlobs::problem_set_registry());
  const auto rows =
      nlobs::reference::run_suite(*selection.set, selection.problems,
                                  {"newton", "kinsol:newton", "minpack:hybrj", "gsl:hybridsj"});
  int solved = 0;
  for (const auto& row : rows) {
    std::printf("%s %s %s %s\n", row.problem.c_str(), row.start.c_str(), row.solver.c_str(),
                row.solved ? "solved" : row.status.c_str());
    solved += row.solved;
  }
  return rows.size() == 8 && solved == 8 ? 0 : 1;
}
