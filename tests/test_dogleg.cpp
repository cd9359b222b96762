// The dogleg engine (Powell's hybrid method): known roots, a singular Jacobian at the root and at
// the start, a far start, a model that leaves its domain, a non-finite start, the budget, the
// trust region's monotone ‖F‖₂, Broyden updates, fixed vs dynamic sizes, and bad options; on the
// MGH set it is compared with MINPACK's hybrj configured as its published driver.
#include <gtest/gtest.h>

#include <cmath>

#include "nlobs/reference/root_reference.hpp"
#include "nlobs/registry/problem_sets/mgh_problems.hpp"
#include "nlobs/solvers/builtin_engines.hpp"
#include "test_support.hpp"

namespace nlobs {
namespace {

using test::circle_line;
using test::strict;

TEST(Dogleg, SolvesASmallSystemToMachinePrecision) {
  DoglegEngine<2> dogleg({}, strict());
  Vector<2> x(1.0, 2.0);
  const Summary s = dogleg.solve(to_fixed_point(circle_line()), x);
  ASSERT_TRUE(s.converged()) << s.full_report();
  EXPECT_NEAR(x[0], std::sqrt(2.0), 1e-13);
  EXPECT_NEAR(x[1], std::sqrt(2.0), 1e-13);
  EXPECT_EQ(s.engine, "dogleg");
  EXPECT_LE(s.residual_norm, 1e-12);
  // Broyden updates between Jacobians: fewer Jacobians than iterations.
  EXPECT_LT(s.jacobian_evaluations, s.iterations);
}

TEST(Dogleg, EveryAcceptedStepDecreasesTheResidual) {
  // Rosenbrock from MINPACK's start ×10: long curved valley; ‖F‖₂ must never go up.
  const reference::MghCase c = reference::mgh_case(1, 2);
  SolverOptions o = strict();
  o.record_trace = true;
  DoglegEngine<> dogleg({}, o);
  Eigen::VectorXd x = c.start(10.0);
  const Summary s = dogleg.solve(to_fixed_point(c.problem), x);
  ASSERT_TRUE(s.converged()) << s.full_report();
  EXPECT_LT((x - Eigen::VectorXd::Ones(2)).norm(), 1e-10);
  Eigen::VectorXd f(2);
  c.problem.evaluate(c.start(10.0), f);
  double previous = f.norm();
  for (const TraceEntry& t : s.trace) {
    c.problem.evaluate(t.x, f);
    EXPECT_LE(f.norm(), previous) << "iteration " << t.iteration;
    previous = f.norm();
  }
}

TEST(Dogleg, PowellSingularRootIsReachedWithoutASingularJacobianStatus) {
  // The Jacobian is singular at the root x = 0: convergence is linear, not an error.
  const reference::MghCase c = reference::mgh_case(2, 4);
  SolverOptions o = test::tolerance(1e-12);
  o.stop.residual_tolerance = 1e-10;
  DoglegEngine<> dogleg({}, o);
  Eigen::VectorXd x = c.start(1.0);
  const Summary s = dogleg.solve(to_fixed_point(c.problem), x);
  EXPECT_TRUE(s.converged()) << s.full_report();
  EXPECT_LT(x.lpNorm<Eigen::Infinity>(), 1e-2);
  EXPECT_LE(s.residual_norm, 1e-10);
}

TEST(Dogleg, LeavesASingularJacobianAtTheStartWhereNewtonStops) {
  // F(x) = x² − 1 at x0 = 0: J = 0. Newton has no step; the dogleg's regularised direction and
  // the trust region find the root.
  const auto problem = to_fixed_point(RootProblem<1>::with_autodiff([](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    Eigen::Matrix<T, 1, 1> f;
    f[0] = x[0] * x[0] - 1.0;
    return f;
  }));
  Vector<1> x(0.0);
  EXPECT_EQ(NewtonEngine<1>({}, strict()).solve(problem, x).status, Status::kSingularJacobian);
  x[0] = 0.0;
  const Summary s = DoglegEngine<1>({}, strict()).solve(problem, x);
  ASSERT_TRUE(s.converged()) << s.full_report();
  EXPECT_NEAR(std::abs(x[0]), 1.0, 1e-12);
}

TEST(Dogleg, AModelThatLeavesItsDomainShrinksTheRegion) {
  // F(x) = log x + 5 from x0 = 1: the Newton step lands at x = −4, where F is NaN. A NaN trial is
  // a failed step: the radius shrinks until the step stays in the domain.
  const auto problem = to_fixed_point(RootProblem<1>::with_autodiff([](const auto& x) {
    using std::log;
    using T = typename std::decay_t<decltype(x)>::Scalar;
    Eigen::Matrix<T, 1, 1> f;
    f[0] = log(x[0]) + 5.0;
    return f;
  }));
  Vector<1> x(1.0);
  const Summary s = DoglegEngine<1>({}, strict()).solve(problem, x);
  ASSERT_TRUE(s.converged()) << s.full_report();
  EXPECT_NEAR(x[0], std::exp(-5.0), 1e-14);
}

TEST(Dogleg, ManyNonFiniteTrialsInARowAreNotStagnation) {
  // log x + 5 from x0 = 1e6: the radius is halved through a long run of NaN trials (x < 0)
  // before a step lands in the domain; those trials are not Jacobians without progress.
  const auto problem = to_fixed_point(RootProblem<1>::with_autodiff([](const auto& x) {
    using std::log;
    using T = typename std::decay_t<decltype(x)>::Scalar;
    Eigen::Matrix<T, 1, 1> f;
    f[0] = log(x[0]) + 5.0;
    return f;
  }));
  Vector<1> x(1e6);
  const Summary s = DoglegEngine<1>({}, strict()).solve(problem, x);
  ASSERT_TRUE(s.converged()) << s.full_report();
  EXPECT_NEAR(x[0], std::exp(-5.0), 1e-14);
}

TEST(Dogleg, FiniteDifferenceJacobiansStayWithinTheBudget) {
  const reference::MghCase c = reference::mgh_case(4, 4);  // Wood, no Jacobian given below
  const auto no_jacobian = FixedPointProblem<>::from_map(
      [&c](const Eigen::VectorXd& x, Eigen::VectorXd& g) {
        c.problem.evaluate(x, g);
        g += x;
      },
      4);
  for (const int budget : {1, 8, 9, 10, 17, 30}) {
    SolverOptions o = strict();
    o.stop.max_evaluations = budget;
    Eigen::VectorXd x = c.start(1.0);
    const Summary s = DoglegEngine<>({}, o).solve(no_jacobian, x);  // central: 8 per Jacobian
    EXPECT_LE(s.function_evaluations, budget) << s.full_report();
    EXPECT_EQ(s.status, Status::kMaxEvaluations) << budget;
  }
}

TEST(Dogleg, FarStartsOfTheHelicalValley) {
  const reference::MghCase c = reference::mgh_case(5, 3);
  for (const double scale : {1.0, 10.0, 100.0}) {
    DoglegEngine<> dogleg({}, strict());
    Eigen::VectorXd x = c.start(scale);
    const Summary s = dogleg.solve(to_fixed_point(c.problem), x);
    EXPECT_TRUE(s.converged()) << "x" << scale << ": " << s.full_report();
    EXPECT_LT((x - Eigen::Vector3d(1.0, 0.0, 0.0)).norm(), 1e-10) << scale;
  }
}

TEST(Dogleg, BadlyScaledProblemIsSolvedWithEitherScaling) {
  // Powell's badly scaled function: x1 x2 = 1e-4 with x1 ≈ 1e-5, x2 ≈ 9.1.
  const reference::MghCase c = reference::mgh_case(3, 2);
  for (const auto scaling :
       {DoglegOptions::Scaling::kNone, DoglegOptions::Scaling::kJacobianColumns}) {
    DoglegEngine<> dogleg({.scaling = scaling}, strict());
    Eigen::VectorXd x = c.start(1.0);
    const Summary s = dogleg.solve(to_fixed_point(c.problem), x);
    EXPECT_TRUE(s.converged()) << s.full_report();
    EXPECT_NEAR(x[0] * x[1], 1e-4, 1e-15);
  }
}

TEST(Dogleg, WithoutBroydenUpdatesEveryIterateHasAFreshJacobian) {
  const reference::MghCase c = reference::mgh_case(4, 4);  // Wood
  DoglegEngine<> broyden({}, strict());
  DoglegEngine<> newton({.broyden_updates = false}, strict());
  Eigen::VectorXd xb = c.start(1.0), xn = c.start(1.0);
  const Summary sb = broyden.solve(to_fixed_point(c.problem), xb);
  const Summary sn = newton.solve(to_fixed_point(c.problem), xn);
  ASSERT_TRUE(sb.converged()) << sb.full_report();
  ASSERT_TRUE(sn.converged()) << sn.full_report();
  EXPECT_LT((xb - xn).norm(), 1e-9);
  EXPECT_LT(sb.jacobian_evaluations, sn.jacobian_evaluations);
  EXPECT_GE(sn.jacobian_evaluations, sn.iterations);
}

TEST(Dogleg, FixedAndDynamicSizesGiveTheSameIterates) {
  const auto fixed = to_fixed_point(circle_line());
  const auto dynamic = FixedPointProblem<>::from_map(
      [&fixed](const Eigen::VectorXd& x, Eigen::VectorXd& g) {
        Vector<2> gx;
        fixed.evaluate(Vector<2>(x), gx);
        g = gx;
      },
      2);
  DoglegEngine<2> a({.finite_difference = FiniteDifference::kForward}, strict());
  DoglegEngine<> b({.finite_difference = FiniteDifference::kForward}, strict());
  // The same finite-difference Jacobian on both sides.
  const auto fixed_fd = FixedPointProblem<2>::from_map(
      [&fixed](const Vector<2>& x, Vector<2>& g) { fixed.evaluate(x, g); });
  Vector<2> xa(3.0, -1.0);
  Eigen::VectorXd xb = Eigen::Vector2d(3.0, -1.0);
  const Summary sa = a.solve(fixed_fd, xa);
  const Summary sb = b.solve(dynamic, xb);
  ASSERT_TRUE(sa.converged()) << sa.full_report();
  EXPECT_EQ(sa.iterations, sb.iterations);
  EXPECT_EQ(sa.function_evaluations, sb.function_evaluations);
  EXPECT_NEAR(xa[0], xb[0], 1e-13);
  EXPECT_NEAR(xa[1], xb[1], 1e-13);
}

TEST(Dogleg, NonFiniteStartAndBudget) {
  const auto nan_everywhere = FixedPointProblem<2>::from_map(
      [](const Vector<2>&, Vector<2>& g) { g.setConstant(std::nan("")); });
  Vector<2> x(1.0, 1.0);
  const Summary s = DoglegEngine<2>({}, strict()).solve(nan_everywhere, x);
  EXPECT_EQ(s.status, Status::kNonFinite);
  EXPECT_EQ(x, Vector<2>(1.0, 1.0));
  EXPECT_FALSE(s.usable());

  // Rosenbrock ×100 (7 evaluations to solve) within 3: stops at the budget, keeping the best
  // point so far.
  const reference::MghCase c = reference::mgh_case(1, 2);
  SolverOptions o = strict();
  o.stop.max_evaluations = 3;
  Eigen::VectorXd y = c.start(100.0);
  Eigen::VectorXd f(2);
  c.problem.evaluate(y, f);
  const double initial = f.norm();
  const Summary b = DoglegEngine<>({}, o).solve(to_fixed_point(c.problem), y);
  EXPECT_EQ(b.status, Status::kMaxEvaluations) << b.full_report();
  EXPECT_LE(b.function_evaluations, 3);
  c.problem.evaluate(y, f);
  EXPECT_LE(f.norm(), initial);
}

TEST(Dogleg, NoRootEndsStagnatedWithMinpacksReason) {
  // F(x) = x² + 1 has no real root: ‖F‖ stops decreasing at x = 0.
  const auto problem = to_fixed_point(RootProblem<1>::with_autodiff([](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    Eigen::Matrix<T, 1, 1> f;
    f[0] = x[0] * x[0] + 1.0;
    return f;
  }));
  Vector<1> x(2.0);
  const Summary s = DoglegEngine<1>({}, strict()).solve(problem, x);
  EXPECT_EQ(s.status, Status::kStagnated) << s.full_report();
  EXPECT_FALSE(s.message.empty());
  EXPECT_FALSE(s.usable());
  // Ten iterations of less than 0.1 % progress end it near the minimiser x = 0 of ‖F‖.
  EXPECT_LT(std::abs(x[0]), 1e-2);
  EXPECT_LT(s.residual_norm, 1.0 + 1e-4);
}

TEST(Dogleg, BadOptionsAndSpecsAreRefusedByName) {
  for (const double factor : {0.0, -1.0, std::nan(""), HUGE_VAL}) {
    EXPECT_NE(test::message_of([&] {
                DoglegEngine<2>({.initial_radius_factor = factor});
              }).find("initial_radius_factor"),
              std::string::npos);
  }
  auto& registry = EngineRegistry<>::global();
  EXPECT_EQ(registry.create("dogleg:scale=jacobian,factor=1,broyden=0")->name(), "dogleg");
  EXPECT_NE(test::message_of([&] { registry.create("dogleg:scale=columns"); }).find("scale"),
            std::string::npos);
  EXPECT_NE(test::message_of([&] { registry.create("dogleg:factor=0"); }).find("factor"),
            std::string::npos);
  EXPECT_NE(test::message_of([&] { registry.create("dogleg:fd=backward"); }).find("fd"),
            std::string::npos);
  const DoglegEngine<2> defaults;
  EXPECT_EQ(defaults.dogleg_options().initial_radius_factor, 100.0);
}

TEST(Dogleg, AGuessOfTheWrongSizeOrNotFiniteIsRefused) {
  const auto problem = FixedPointProblem<>::from_map(
      [](const Eigen::VectorXd& x, Eigen::VectorXd& g) { g = 0.5 * x; }, 2);
  DoglegEngine<> dogleg;
  Eigen::VectorXd x = Eigen::Vector3d(1.0, 2.0, 3.0);
  EXPECT_NE(test::message_of([&] { dogleg.solve(problem, x); }).find("size 3"), std::string::npos);
  x = Eigen::Vector2d(1.0, std::nan(""));
  EXPECT_NE(test::message_of([&] { dogleg.solve(problem, x); }).find("x0[1]"), std::string::npos);
}

}  // namespace
}  // namespace nlobs
