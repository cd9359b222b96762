// NLopt engine: known minima, bounds, algorithms by name, statuses, bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "nlobs/registry/problem_sets/mgh_problems.hpp"
#include "nlobs/solvers/nlopt_engine.hpp"

namespace nlobs {
namespace {

SolverOptions tight() {
  SolverOptions o;
  o.stop.step_tolerance = 1e-12;
  o.stop.residual_tolerance = 1e-10;
  return o;
}

TEST(NloptEngine, AlgorithmsReachRosenbrocksRoot) {
  const auto c = reference::mgh_case(1, 2);
  for (const char* algorithm : {"LN_BOBYQA", "LN_COBYLA", "LD_SLSQP", "LD_LBFGS"}) {
    NloptEngine<Dynamic> engine({.algorithm = algorithm}, tight());
    Vector<Dynamic> x = c.start(1.0);
    const Summary s = engine.solve(c.problem, x);
    EXPECT_TRUE(s.converged()) << algorithm << '\n' << s.full_report();
    EXPECT_LT((x - Eigen::VectorXd::Ones(2)).lpNorm<Eigen::Infinity>(), 1e-4) << algorithm;
    ASSERT_TRUE(s.objective.has_value());
    EXPECT_EQ(engine.needs_gradient(), algorithm[1] == 'D');
    if (engine.needs_gradient()) {
      EXPECT_GT(s.jacobian_evaluations, 0) << algorithm;
    }
  }
}

TEST(NloptEngine, GlobalAlgorithmInsideFiniteBox) {
  // ½‖F‖² for F(x) = (x1 − 0.3, x2 + 0.6) on [−1, 1]²: DIRECT-L finds the minimum.
  const auto f = RootProblem<2>::from_map(
      [](const Vector<2>& x, Vector<2>& r) { r << x[0] - 0.3, x[1] + 0.6; });
  SolverOptions o;
  o.stop.step_tolerance = 1e-4;
  o.stop.max_evaluations = 4000;
  NloptEngine<2> engine({.algorithm = "GN_DIRECT_L",
                         .lower_bounds = Eigen::Vector2d(-1, -1),
                         .upper_bounds = Eigen::Vector2d(1, 1)},
                        o);
  Vector<2> x(0.0, 0.0);
  engine.solve(f, x);
  EXPECT_NEAR(x[0], 0.3, 1e-3);
  EXPECT_NEAR(x[1], -0.6, 1e-3);
}

TEST(NloptEngine, BoundedMinimumLandsOnTheBound) {
  // min (x1 − 2)² + (x2 + 1)² on [−1, 1]²: the unconstrained minimum (2, −1) is outside;
  // the bounded one is (1, −1).
  const auto q = ObjectiveProblem<2>::with_autodiff(
      [](const auto& x) { return (x[0] - 2.0) * (x[0] - 2.0) + (x[1] + 1.0) * (x[1] + 1.0); });
  for (const char* algorithm : {"LN_BOBYQA", "LD_SLSQP", "LD_LBFGS", "LN_COBYLA"}) {
    NloptEngine<2> engine({.algorithm = algorithm,
                           .lower_bounds = Eigen::Vector2d(-1, -1),
                           .upper_bounds = Eigen::Vector2d(1, 1)},
                          tight());
    Vector<2> x(0.0, 0.0);
    const Summary s = engine.minimize(q, x);
    EXPECT_TRUE(s.converged()) << algorithm << '\n' << s.full_report();
    EXPECT_NEAR(x[0], 1.0, 1e-6) << algorithm;
    EXPECT_NEAR(x[1], -1.0, 1e-6) << algorithm;
    EXPECT_LE(x[0], 1.0);
    ASSERT_TRUE(s.objective.has_value());
    EXPECT_NEAR(*s.objective, 1.0, 1e-6);
    EXPECT_TRUE(std::isnan(s.residual_norm));  // not a residual problem
  }
}

TEST(NloptEngine, ReusedAcrossSolvesOfSmallBoundedProblems) {
  // The MVT observer's use: many 1-D bounded problems, one engine.
  NloptEngine<1> engine({.algorithm = "LN_BOBYQA",
                         .lower_bounds = Eigen::VectorXd::Zero(1),
                         .upper_bounds = Eigen::VectorXd::Ones(1)},
                        tight());
  for (double target : {-0.5, 0.0, 0.25, 0.8, 1.7}) {
    const auto q = ObjectiveProblem<1>::with_autodiff(
        [target](const auto& b) { return (b[0] - target) * (b[0] - target); });
    Vector<1> b(0.5);
    engine.minimize(q, b);
    EXPECT_NEAR(b[0], std::clamp(target, 0.0, 1.0), 1e-6) << target;
  }
}

TEST(NloptEngine, GradientSources) {
  const auto value = [](const auto& x) { return (x[0] - 1.0) * (x[0] - 1.0) + 3.0 * x[1] * x[1]; };
  const auto by_ad = ObjectiveProblem<2>::with_autodiff(value);
  const auto by_user = ObjectiveProblem<2>::with_gradient(
      [value](const Vector<2>& x) { return value(x); },
      [](const Vector<2>& x, Vector<2>& g) { g << 2.0 * (x[0] - 1.0), 6.0 * x[1]; });
  const auto by_fd =
      ObjectiveProblem<2>::from_function([value](const Vector<2>& x) { return value(x); });
  for (const auto* p : {&by_ad, &by_user, &by_fd}) {
    NloptEngine<2> engine({.algorithm = "LD_LBFGS"}, tight());
    Vector<2> x(3.0, -2.0);
    const Summary s = engine.minimize(*p, x);
    EXPECT_TRUE(s.converged()) << s.full_report();
    EXPECT_NEAR(x[0], 1.0, 1e-5);
    EXPECT_NEAR(x[1], 0.0, 1e-5);
  }
  Vector<2> g;
  by_ad.gradient(Vector<2>(2.0, 1.0), g);
  EXPECT_NEAR(g[0], 2.0, 1e-15);
  EXPECT_NEAR(g[1], 6.0, 1e-15);
}

TEST(NloptEngine, StatusesMaxEvaluationsAndNonFinite) {
  SolverOptions o = tight();
  o.stop.max_evaluations = 7;
  const auto c = reference::mgh_case(1, 2);
  NloptEngine<Dynamic> engine({.algorithm = "LN_BOBYQA"}, o);
  Vector<Dynamic> x = c.start(1.0);
  EXPECT_EQ(engine.solve(c.problem, x).status, Status::kMaxEvaluations);

  const auto nan_far = ObjectiveProblem<1>::from_function(
      [](const Vector<1>& v) { return v[0] < 3.0 ? (v[0] - 5.0) * (v[0] - 5.0) : std::nan(""); });
  NloptEngine<1> e1({.algorithm = "LN_BOBYQA", .initial_step = 2.5});
  Vector<1> y(0.0);
  const Summary s = e1.minimize(nan_far, y);
  EXPECT_EQ(s.status, Status::kNonFinite) << s.full_report();
  EXPECT_TRUE(std::isfinite(y[0]));
}

TEST(NloptEngine, BadInputRaises) {
  try {
    NloptEngine<2> e({.algorithm = "LN_NOPE"});
    FAIL();
  } catch (const InvalidInput& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("'LN_NOPE' is not an NLopt algorithm"), std::string::npos) << m;
    EXPECT_NE(m.find("LN_BOBYQA"), std::string::npos) << m;  // lists the valid ones
  }
  EXPECT_THROW(NloptEngine<2>(
                   {.lower_bounds = Eigen::Vector2d(0, 1), .upper_bounds = Eigen::Vector2d(1, 0)}),
               InvalidInput);
  EXPECT_THROW(NloptEngine<2>({.algorithm = "GN_DIRECT_L"}), InvalidInput);  // needs a box
  EXPECT_THROW(NloptEngine<2>({.algorithm = "GN_DIRECT_L",
                               .lower_bounds = Eigen::Vector2d(0, -INFINITY),
                               .upper_bounds = Eigen::Vector2d(1, 1)}),
               InvalidInput);
  NloptEngine<2> boxed(
      {.lower_bounds = Eigen::Vector2d(0, 0), .upper_bounds = Eigen::Vector2d(1, 1)});
  const auto q = ObjectiveProblem<2>::with_autodiff([](const auto& x) { return x[0] * x[1]; });
  Vector<2> x(0.5, 1.5);
  try {
    boxed.minimize(q, x);
    FAIL();
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("x0[1] = 1.5"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace nlobs
