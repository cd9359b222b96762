// The broyden engine (Broyden's good method with a line search and Jacobian restarts): known
// roots, a badly scaled system, a singular Jacobian at the root (Powell singular), far starts
// (×100), a model that leaves its domain, restarts, the budget with difference Jacobians, F NaN
// everywhere, fixed vs dynamic sizes, and bad options.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "nlobs/registry/problem_sets/mgh_problems.hpp"
#include "nlobs/solvers/builtin_engines.hpp"
#include "test_support.hpp"

namespace nlobs {
namespace {

using test::circle_line;
using test::strict;

TEST(Broyden, SolvesASmallSystemWithFewerJacobiansThanIterations) {
  BroydenEngine<2> broyden({}, strict());
  Vector<2> x(1.0, 2.0);
  const Summary s = broyden.solve(to_fixed_point(circle_line()), x);
  ASSERT_TRUE(s.converged()) << s.full_report();
  EXPECT_NEAR(x[0], std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(x[1], std::sqrt(2.0), 1e-12);
  EXPECT_EQ(s.engine, "broyden");
  EXPECT_EQ(s.jacobian_evaluations, 1);  // rank-one updates do the rest
  EXPECT_GT(s.iterations, 3);            // superlinear, not quadratic
}

TEST(Broyden, MghProblemsFromNearAndFarStarts) {
  // Rosenbrock ×1 and ×100, Powell singular (J singular at the root), Powell badly scaled,
  // helical valley ×10.
  struct Case {
    int number, n;
    double scale;
  };
  for (const Case c :
       {Case{1, 2, 1.0}, Case{1, 2, 100.0}, Case{2, 4, 1.0}, Case{3, 2, 1.0}, Case{5, 3, 10.0}}) {
    const reference::MghCase p = reference::mgh_case(c.number, c.n);
    SolverOptions o = test::tolerance(1e-12);
    o.stop.residual_tolerance = 1e-10;
    BroydenEngine<> broyden({}, o);
    Eigen::VectorXd x = p.start(c.scale);
    const Summary s = broyden.solve(to_fixed_point(p.problem), x);
    EXPECT_TRUE(s.usable()) << p.name << " x" << c.scale << ": " << s.brief_report();
    Eigen::VectorXd f(c.n);
    p.problem.evaluate(x, f);
    EXPECT_LT(f.norm(), 1e-8) << p.name << " x" << c.scale;
  }
}

TEST(Broyden, AStaleUpdateIsReplacedByAFreshJacobian) {
  // max_updates = 1: a fresh Jacobian every second iterate; the same root.
  BroydenEngine<2> often({.max_updates = 1}, strict()), never({}, strict());
  Vector<2> a(1.0, 2.0), b(1.0, 2.0);
  const Summary so = often.solve(to_fixed_point(circle_line()), a);
  const Summary sn = never.solve(to_fixed_point(circle_line()), b);
  ASSERT_TRUE(so.converged() && sn.converged());
  EXPECT_GT(so.jacobian_evaluations, sn.jacobian_evaluations);
  EXPECT_NEAR((a - b).norm(), 0.0, 1e-12);
}

TEST(Broyden, AModelThatLeavesItsDomainBacktracks) {
  // F(x) = log x + 5 from x0 = 1: the first step lands at x = −4, where F is NaN.
  const auto f = RootProblem<1>::with_autodiff([](const auto& x) {
    using std::log;
    using T = typename std::decay_t<decltype(x)>::Scalar;
    return Eigen::Matrix<T, 1, 1>(log(x[0]) + 5.0);
  });
  BroydenEngine<1> broyden({}, strict());
  Vector<1> x(1.0);
  const Summary s = broyden.solve(to_fixed_point(f), x);
  ASSERT_TRUE(s.converged()) << s.full_report();
  EXPECT_NEAR(x[0], std::exp(-5.0), 1e-14);
}

TEST(Broyden, NoRootEndsStagnatedAndNotUsable) {
  // x² + 1: the line search finds no decrease at the minimum of |F|, x = 0.
  const auto f = RootProblem<1>::with_autodiff([](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    return Eigen::Matrix<T, 1, 1>(x[0] * x[0] + 1.0);
  });
  BroydenEngine<1> broyden({}, strict());
  Vector<1> x(3.0);
  const Summary s = broyden.solve(to_fixed_point(f), x);
  EXPECT_FALSE(s.usable()) << s.brief_report();
  EXPECT_TRUE(s.status == Status::kStagnated || s.status == Status::kSingularJacobian)
      << s.brief_report();
}

TEST(Broyden, DifferenceJacobiansNeverOverrunTheBudget) {
  const reference::MghCase p = reference::mgh_case(4, 4);  // Wood
  for (const int budget : {3, 7, 12, 40}) {
    SolverOptions o = strict();
    o.stop.max_evaluations = budget;
    BroydenEngine<> broyden({}, o);
    Eigen::VectorXd x = p.start(1.0);
    const auto g = FixedPointProblem<>::from_map(
        [&p](const Eigen::VectorXd& v, Eigen::VectorXd& out) {
          out.resize(v.size());
          p.problem.evaluate(v, out);
          out += v;
        },
        4);
    const Summary s = broyden.solve(g, x);
    EXPECT_LE(s.function_evaluations, budget) << s.brief_report();
    EXPECT_EQ(s.status, Status::kMaxEvaluations) << budget;
    EXPECT_TRUE(x.allFinite());
  }
}

TEST(Broyden, NonFiniteEverywhereKeepsTheStart) {
  const auto g = FixedPointProblem<2>::from_map([](const Vector<2>&, Vector<2>& out) {
    out.setConstant(std::numeric_limits<double>::quiet_NaN());
  });
  BroydenEngine<2> broyden({}, strict());
  Vector<2> x(1.0, 2.0);
  const Summary s = broyden.solve(g, x);
  EXPECT_EQ(s.status, Status::kNonFinite);
  EXPECT_EQ(x, Vector<2>(1.0, 2.0));
  EXPECT_FALSE(s.usable());
}

TEST(Broyden, FixedAndDynamicSizesGiveTheSameIterates) {
  BroydenEngine<2> fixed({}, strict());
  BroydenEngine<> dynamic({}, strict());
  Vector<2> a(1.0, 2.0);
  Eigen::VectorXd b = a;
  const auto problem = circle_line();
  const Summary sa = fixed.solve(to_fixed_point(problem), a);
  const auto dyn = RootProblem<>::with_autodiff(
      [](const auto& x, auto& f) {
        f.resize(2);
        f << x[0] * x[0] + x[1] * x[1] - 4.0, x[0] - x[1];
      },
      2, 2);
  const Summary sb = dynamic.solve(to_fixed_point(dyn), b);
  EXPECT_EQ(sa.iterations, sb.iterations);
  EXPECT_EQ(sa.function_evaluations, sb.function_evaluations);
  EXPECT_NEAR((a - b).norm(), 0.0, 1e-14);
}

TEST(Broyden, BadOptionsAreRefusedByName) {
  EXPECT_NE(test::message_of([] {
              BroydenEngine<2>({.max_backtracks = -1});
            }).find("BroydenOptions::max_backtracks = -1"),
            std::string::npos);
  EXPECT_NE(test::message_of([] {
              BroydenEngine<2>({.sufficient_decrease = 0.5});
            }).find("BroydenOptions::sufficient_decrease = 0.5"),
            std::string::npos);
  EXPECT_NE(test::message_of([] {
              BroydenEngine<2>({.max_updates = -3});
            }).find("BroydenOptions::max_updates = -3"),
            std::string::npos);
  auto& registry = EngineRegistry<2>::global();
  EXPECT_EQ(registry.create("broyden:backtracks=4,updates=20,fd=forward")->name(), "broyden");
  EXPECT_NE(test::message_of([&] { registry.create("broyden:backtracks=61"); }).find("backtracks"),
            std::string::npos);
  EXPECT_NE(test::message_of([&] { registry.create("broyden:fd=sideways"); }).find("fd=sideways"),
            std::string::npos);
}

}  // namespace
}  // namespace nlobs
