// Ceres engine: known solutions, both back ends, bounds, statuses, bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "nlobs/registry/problem_sets/mgh_problems.hpp"
#include "nlobs/solvers/ceres_engine.hpp"
#include "nlobs/solvers/root_adapter.hpp"

namespace nlobs {
namespace {

using reference::mgh_case;

// Rosenbrock as a fixed-size root problem, generic in the scalar.
RootProblem<2> rosenbrock() {
  return RootProblem<2>::with_autodiff([](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    Eigen::Matrix<T, 2, 1> f;
    f << 1.0 - x[0], 10.0 * (x[1] - x[0] * x[0]);
    return f;
  });
}

SolverOptions tight() {
  SolverOptions o;
  o.stop.step_tolerance = 1e-14;
  o.stop.residual_tolerance = 1e-12;
  return o;
}

TEST(CeresEngine, BothBackEndsSolveRosenbrock) {
  for (auto backend : {CeresOptions::Backend::kTinySolver, CeresOptions::Backend::kSolver}) {
    CeresEngine<2> engine({.backend = backend}, tight());
    EXPECT_EQ(engine.uses_tiny_solver(), backend == CeresOptions::Backend::kTinySolver);
    Vector<2> x(-1.2, 1.0);
    const Summary s = engine.solve(rosenbrock(), x);
    EXPECT_TRUE(s.converged()) << s.full_report();
    EXPECT_NEAR(x[0], 1.0, 1e-10);
    EXPECT_NEAR(x[1], 1.0, 1e-10);
    EXPECT_LE(s.residual_norm, 1e-10);
    EXPECT_GT(s.jacobian_evaluations, 0);
    EXPECT_GE(s.function_evaluations, s.jacobian_evaluations);
  }
  CeresEngine<2> automatic;
  EXPECT_TRUE(automatic.uses_tiny_solver());  // fixed size, LM, no bounds
  CeresEngine<Dynamic> dynamic;
  EXPECT_FALSE(dynamic.uses_tiny_solver());
}

TEST(CeresEngine, ReachesKnownSolutionsOfSuiteProblems) {
  struct Known {
    int number, n;
    Eigen::VectorXd root;
  };
  // Problems with a single root (Wood's F is a gradient with several zeros: not here).
  const std::vector<Known> known = {
      {1, 2, Eigen::VectorXd::Ones(2)},                          // Rosenbrock
      {5, 3, (Eigen::VectorXd(3) << 1.0, 0.0, 0.0).finished()},  // helical valley
      {12, 10, Eigen::VectorXd::Ones(10)},                       // variably dimensioned
  };
  for (auto method : {CeresOptions::Method::kLevenbergMarquardt, CeresOptions::Method::kDogleg}) {
    for (const Known& k : known) {
      const auto c = mgh_case(k.number, k.n);
      CeresEngine<Dynamic> engine({.method = method}, tight());
      Vector<Dynamic> x = c.start(1.0);
      const Summary s = engine.solve(c.problem, x);
      EXPECT_TRUE(s.converged()) << c.name << '\n' << s.full_report();
      EXPECT_LT((x - k.root).lpNorm<Eigen::Infinity>(), 1e-7) << c.name;
    }
    // Wood: some zero of F (the gradient of Wood's function), not necessarily (1, 1, 1, 1).
    const auto wood = mgh_case(4, 4);
    CeresEngine<Dynamic> engine({.method = method}, tight());
    Vector<Dynamic> x = wood.start(1.0);
    EXPECT_TRUE(engine.solve(wood.problem, x).converged());
    Vector<Dynamic> f(4);
    wood.problem.evaluate(x, f);
    EXPECT_LT(f.norm(), 1e-8);
  }
  // Powell singular: the root 0 is a singular point; convergence is linear but gets there.
  const auto powell = mgh_case(2, 4);
  CeresEngine<Dynamic> engine({}, tight());
  Vector<Dynamic> x = powell.start(1.0);
  engine.solve(powell.problem, x);
  EXPECT_LT(x.lpNorm<Eigen::Infinity>(), 1e-3);
}

TEST(CeresEngine, OverdeterminedLeastSquares) {
  // Fit y = a exp(b t) to exact data: m = 6 residuals, n = 2 unknowns.
  const auto fit = RootProblem<2, 6>::with_autodiff([](const auto& p) {
    using std::exp;
    using T = typename std::decay_t<decltype(p)>::Scalar;
    Eigen::Matrix<T, 6, 1> r;
    for (int i = 0; i < 6; ++i) {
      const double t = 0.2 * i;
      r[i] = p[0] * exp(p[1] * t) - 2.0 * std::exp(-0.7 * t);
    }
    return r;
  });
  for (auto backend : {CeresOptions::Backend::kTinySolver, CeresOptions::Backend::kSolver}) {
    CeresEngine<2> engine({.backend = backend}, tight());
    Vector<2> p(1.0, 0.0);
    const Summary s = engine.solve(fit, p);
    EXPECT_TRUE(s.converged()) << s.full_report();
    EXPECT_NEAR(p[0], 2.0, 1e-9);
    EXPECT_NEAR(p[1], -0.7, 1e-9);
  }
}

TEST(CeresEngine, BoundsAreRespected) {
  // F(x) = x − 3 (minimum of ½F² at 3), box [−1, 2]: the answer is the bound 2.
  const auto f = RootProblem<1>::with_autodiff([](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    Eigen::Matrix<T, 1, 1> r;
    r[0] = x[0] - 3.0;
    return r;
  });
  CeresEngine<1> engine({.lower_bounds = Eigen::VectorXd::Constant(1, -1.0),
                         .upper_bounds = Eigen::VectorXd::Constant(1, 2.0)},
                        tight());
  EXPECT_FALSE(engine.uses_tiny_solver());
  Vector<1> x(0.0);
  const Summary s = engine.solve(f, x);
  EXPECT_TRUE(s.converged()) << s.full_report();
  EXPECT_LE(x[0], 2.0);
  EXPECT_NEAR(x[0], 2.0, 1e-8);
  EXPECT_NEAR(s.residual_norm, 1.0, 1e-8);  // honest: a bounded minimum, not a root
}

TEST(CeresEngine, InvalidBoundsAndBackEndsRaise) {
  EXPECT_THROW(CeresEngine<1>({.lower_bounds = Eigen::VectorXd::Constant(1, 1.0),
                               .upper_bounds = Eigen::VectorXd::Constant(1, 0.0)}),
               InvalidInput);
  EXPECT_THROW(CeresEngine<1>({.backend = CeresOptions::Backend::kTinySolver,
                               .lower_bounds = Eigen::VectorXd::Zero(1)}),
               InvalidInput);
  EXPECT_THROW(CeresEngine<Dynamic>({.backend = CeresOptions::Backend::kTinySolver}), InvalidInput);
  EXPECT_THROW(CeresEngine<1>({.method = CeresOptions::Method::kDogleg,
                               .backend = CeresOptions::Backend::kTinySolver}),
               InvalidInput);
  CeresEngine<2> boxed({.lower_bounds = Eigen::VectorXd::Zero(2)});
  Vector<2> x(0.5, -0.25);
  try {
    boxed.solve(rosenbrock(), x);
    FAIL() << "x0 outside the box was accepted";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("x0[1] = -0.25"), std::string::npos) << e.what();
  }
  CeresEngine<Dynamic> sized({.upper_bounds = Eigen::VectorXd::Ones(3)});
  Vector<Dynamic> y = Vector<Dynamic>::Zero(2);
  EXPECT_THROW(sized.solve(to_fixed_point<Dynamic>(RootProblem<Dynamic>::from_map(
                               [](const Vector<Dynamic>& v, Vector<Dynamic>& o) { o = v; }, 2, 2)),
                           y),
               InvalidInput);
}

TEST(CeresEngine, StatusesMaxEvaluationsAndNonFinite) {
  SolverOptions o = tight();
  o.stop.max_evaluations = 3;
  for (auto backend : {CeresOptions::Backend::kTinySolver, CeresOptions::Backend::kSolver}) {
    CeresEngine<2> engine({.backend = backend}, o);
    Vector<2> x(-1.2, 1.0);
    const Summary s = engine.solve(rosenbrock(), x);
    EXPECT_EQ(s.status, Status::kMaxEvaluations) << s.full_report();
    EXPECT_TRUE(x.allFinite());
  }
  // F is NaN everywhere but at the start: the engine reports it and keeps the start.
  const auto nan_away = RootProblem<1>::from_map([](const Vector<1>& x, Vector<1>& f) {
    f[0] = x[0] == 1.0 ? 1.0 : std::numeric_limits<double>::quiet_NaN();
  });
  for (auto backend : {CeresOptions::Backend::kTinySolver, CeresOptions::Backend::kSolver}) {
    CeresEngine<1> engine({.backend = backend});
    Vector<1> x(1.0);
    const Summary s = engine.solve(nan_away, x);
    EXPECT_EQ(s.status, Status::kNonFinite) << s.full_report();
    EXPECT_EQ(x[0], 1.0);
  }
}

TEST(CeresEngine, FullReportOnRequest) {
  CeresEngine<Dynamic> engine({.method = CeresOptions::Method::kDogleg});
  const auto c = mgh_case(1, 2);
  Vector<Dynamic> x = c.start(1.0);
  engine.solve(c.problem, x);
  EXPECT_NE(engine.ceres_summary().FullReport().find("DOGLEG"), std::string::npos);
}

}  // namespace
}  // namespace nlobs
