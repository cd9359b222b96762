#include "nlobs/registry/problem_sets/bounded_set.hpp"

#include <cmath>
#include <numbers>

namespace nlobs {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kE = std::numbers::e;

TestProblem ferraris_tronconi() {
  auto f = [](const auto& x, auto& out) {
    using std::exp;
    using std::sin;
    out[0] = 0.5 * sin(x[0] * x[1]) - x[1] / (4.0 * kPi) - x[0] / 2.0;
    out[1] = (1.0 - 1.0 / (4.0 * kPi)) * (exp(2.0 * x[0]) - kE) + kE * x[1] / kPi - 2.0 * kE * x[0];
  };
  TestProblem p = root_test_problem("ferraris-tronconi", 2, f,
                                    {{"a", Eigen::Vector2d(0.4, 3.0)},
                                     {"b", Eigen::Vector2d(0.9, 6.0)},
                                     {"corner", Eigen::Vector2d(0.25, 1.5)}});
  p.lower = Eigen::Vector2d(0.25, 1.5);
  p.upper = Eigen::Vector2d(1.0, 2.0 * kPi);
  // Published (Floudas 14.1.4) as (0.29945, 2.83693), where ‖F‖₂ = 1e-6: refined by Newton to
  // double precision, as a known solution must be a root at the set's threshold.
  p.solutions = {Eigen::Vector2d(0.29944869249092626, 2.8369277704589395),
                 Eigen::Vector2d(0.5, kPi)};
  p.description = "Ferraris-Tronconi, two roots in [0.25, 1] x [1.5, 2 pi] (Floudas 14.1.4)";
  return p;
}

TestProblem bullard_biegler() {
  auto f = [](const auto& x, auto& out) {
    using std::exp;
    out[0] = 1e4 * x[0] * x[1] - 1.0;
    out[1] = exp(-x[0]) + exp(-x[1]) - 1.001;
  };
  TestProblem p =
      root_test_problem("bullard-biegler", 2, f,
                        {{"a", Eigen::Vector2d(0.1, 1.0)}, {"b", Eigen::Vector2d(4.0, 0.01)}});
  p.lower = Eigen::Vector2d(5.49e-6, 2.196e-3);
  p.upper = Eigen::Vector2d(4.553, 18.21);
  // Published as (1.450e-5, 6.8933353), where ‖F‖₂ = 5e-4: refined by Newton.
  p.solutions = {Eigen::Vector2d(1.4506728712044511e-05, 6.8933528698977415)};
  p.description = "Bullard-Biegler: Powell's badly scaled system with 1.001, on a box";
  return p;
}

TestProblem shacham_cstr() {
  auto f = [](const auto& x, auto& out) {
    using std::log;
    out[0] = x[0] / (1.0 - x[0]) - 5.0 * log(0.4 * (1.0 - x[0]) / (0.4 - 0.5 * x[0])) + 4.45977;
  };
  TestProblem p = root_test_problem(
      "shacham-cstr", 1, f,
      {{"a", Eigen::VectorXd::Constant(1, 0.0)}, {"b", Eigen::VectorXd::Constant(1, 0.5)}});
  p.lower = Eigen::VectorXd::Constant(1, 0.0);
  // x < 0.8 strictly: at 0.8 the log's argument is 0.4 · 0.2 / 0 (the box used to stop at
  // 0.7999 for want of strict bounds).
  p.upper = Eigen::VectorXd::Constant(1, 0.8);
  p.strict_upper = StrictBounds::Constant(1, true);
  // Published as 0.757396, where |F| = 2e-5: refined by Newton.
  p.solutions = {Eigen::VectorXd::Constant(1, 0.7573962462537539)};
  p.description = "Shacham's CSTR conversion, F undefined from x = 0.8 on";
  return p;
}

}  // namespace

ProblemSetEntry bounded_problem_set() {
  ProblemSetEntry set;
  set.name = "bounded";
  set.description =
      "square systems on a box with published solutions (Ferraris-Tronconi, Bullard-Biegler, "
      "Shacham's CSTR); engines that take bounds get the box";
  set.problems = [] {
    std::vector<TestProblem> problems;
    problems.push_back(ferraris_tronconi());
    problems.push_back(bullard_biegler());
    problems.push_back(shacham_cstr());
    return problems;
  };
  return set;
}

}  // namespace nlobs
