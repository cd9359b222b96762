// The Levenberg–Marquardt engine (Moré's lmder): square systems with known roots, a
// least-squares fit nlobs does not ship (against Ceres on the same data), a stationary point that
// is not a root, a model that leaves its domain, geodesic acceleration, fixed vs dynamic sizes,
// and bad input.
#include <gtest/gtest.h>

#include <cmath>

#include "nlobs/registry/problem_sets/mgh_problems.hpp"
#include "nlobs/solvers/builtin_engines.hpp"
#include "test_support.hpp"

namespace nlobs {
namespace {

using test::strict;

using Lm = LevenbergMarquardtEngine<>;

// y = a exp(b t) + c sampled at 12 times, with a fixed perturbation of the data.
struct ExponentialFit {
  Eigen::VectorXd t, y;
  explicit ExponentialFit(double noise) : t(12), y(12) {
    for (int i = 0; i < 12; ++i) {
      t[i] = 0.25 * i;
      y[i] = 2.0 * std::exp(-0.7 * t[i]) + 0.5 + noise * std::sin(3.1 * i);
    }
  }
  RootProblem<Dynamic, Dynamic> problem() const {
    const Eigen::VectorXd tt = t, yy = y;
    return RootProblem<Dynamic, Dynamic>::with_autodiff(
        [tt, yy](const auto& p) {
          using T = typename std::decay_t<decltype(p)>::Scalar;
          using std::exp;
          Eigen::Matrix<T, Eigen::Dynamic, 1> r(tt.size());
          for (Index i = 0; i < tt.size(); ++i) r[i] = p[0] * exp(p[1] * tt[i]) + p[2] - yy[i];
          return r;
        },
        3, 12);
  }
};

TEST(LevenbergMarquardt, SolvesSquareSystemsFromMinpacksStarts) {
  struct Case {
    int number, n;
    double scale;
  };
  for (const Case c :
       {Case{1, 2, 1.0}, Case{1, 2, 100.0}, Case{4, 4, 1.0}, Case{5, 3, 10.0}, Case{12, 10, 1.0}}) {
    const reference::MghCase mgh = reference::mgh_case(c.number, c.n);
    Lm lm({}, strict());
    Eigen::VectorXd x = mgh.start(c.scale);
    const Summary s = lm.solve(to_fixed_point(mgh.problem), x);
    EXPECT_TRUE(s.converged()) << mgh.name << " x" << c.scale << ": " << s.full_report();
    EXPECT_LE(s.residual_norm, 1e-12) << mgh.name;
    EXPECT_EQ(s.engine, "levenberg-marquardt");
  }
}

TEST(LevenbergMarquardt, PowellSingularConvergesLinearly) {
  const reference::MghCase c = reference::mgh_case(2, 4);
  SolverOptions o = test::tolerance(1e-12);
  o.stop.residual_tolerance = 1e-10;
  Lm lm({}, o);
  Eigen::VectorXd x = c.start(1.0);
  const Summary s = lm.solve(to_fixed_point(c.problem), x);
  EXPECT_TRUE(s.converged()) << s.full_report();
  EXPECT_LE(s.residual_norm, 1e-10);
}

TEST(LevenbergMarquardt, AUsersExponentialFitMatchesCeres) {
  // Exact data: the residual reaches zero and the parameters are recovered.
  {
    const ExponentialFit fit(0.0);
    Lm lm({}, strict());
    Eigen::VectorXd p = Eigen::Vector3d(1.0, -0.1, 0.0);
    const Summary s = lm.solve_least_squares(fit.problem(), p);
    ASSERT_TRUE(s.converged()) << s.full_report();
    EXPECT_LT((p - Eigen::Vector3d(2.0, -0.7, 0.5)).norm(), 1e-10);
  }
  // Perturbed data: a non-zero minimum; LM and Ceres agree on it.
  const ExponentialFit fit(0.02);
  SolverOptions o = test::tolerance(1e-14);
  Lm lm({}, o);
  Eigen::VectorXd p = Eigen::Vector3d(1.0, -0.1, 0.0);
  const Summary s = lm.solve_least_squares(fit.problem(), p);
  ASSERT_TRUE(s.converged()) << s.full_report();
  EXPECT_TRUE(s.usable()) << s.unusable_reason();
  EXPECT_GT(s.residual_norm, 1e-3);  // the perturbation stays in the residual
  CeresEngine<> ceres({}, o);
  Eigen::VectorXd q = Eigen::Vector3d(1.0, -0.1, 0.0);
  ASSERT_TRUE(ceres.solve_least_squares(fit.problem(), q).converged());
  EXPECT_LT((p - q).norm(), 1e-7) << p.transpose() << " vs " << q.transpose();
  // The gradient Jᵀ F vanishes there (ftol = 1e-10 stops it at |JᵀF| ≈ 1e-9, ‖F‖₂ ≈ 0.05).
  Eigen::MatrixXd j(12, 3);
  Eigen::VectorXd f(12);
  fit.problem().jacobian(p, j);
  fit.problem().evaluate(p, f);
  EXPECT_LT((j.transpose() * f).norm(), 1e-8);
}

TEST(LevenbergMarquardt, AStationaryPointThatIsNotARootIsNamed) {
  // F(x) = x² − 1 at x0 = 0: J = 0 and Jᵀ F = 0; LM cannot leave a stationary point of ‖F‖².
  const auto problem = to_fixed_point(RootProblem<1>::with_autodiff([](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    Eigen::Matrix<T, 1, 1> f;
    f[0] = x[0] * x[0] - 1.0;
    return f;
  }));
  Vector<1> x(0.0);
  const Summary s = LevenbergMarquardtEngine<1>({}, strict()).solve(problem, x);
  EXPECT_EQ(s.status, Status::kStagnated) << s.full_report();
  EXPECT_NE(s.message.find("not a root"), std::string::npos) << s.message;
  EXPECT_FALSE(s.usable());
  // F(x) = x² + 1: no real root; LM ends at the minimum of ‖F‖, x = 0, and says so.
  const auto no_root = to_fixed_point(RootProblem<1>::with_autodiff([](const auto& y) {
    using T = typename std::decay_t<decltype(y)>::Scalar;
    Eigen::Matrix<T, 1, 1> f;
    f[0] = y[0] * y[0] + 1.0;
    return f;
  }));
  x[0] = 2.0;
  const Summary t = LevenbergMarquardtEngine<1>({}, strict()).solve(no_root, x);
  EXPECT_EQ(t.status, Status::kStagnated) << t.full_report();
  EXPECT_FALSE(t.usable());
  EXPECT_LT(std::abs(x[0]), 1e-3);
}

TEST(LevenbergMarquardt, AModelThatLeavesItsDomainShrinksTheRegion) {
  const auto problem = to_fixed_point(RootProblem<1>::with_autodiff([](const auto& x) {
    using std::log;
    using T = typename std::decay_t<decltype(x)>::Scalar;
    Eigen::Matrix<T, 1, 1> f;
    f[0] = log(x[0]) + 5.0;
    return f;
  }));
  Vector<1> x(1.0);
  const Summary s = LevenbergMarquardtEngine<1>({}, strict()).solve(problem, x);
  ASSERT_TRUE(s.converged()) << s.full_report();
  EXPECT_NEAR(x[0], std::exp(-5.0), 1e-14);
}

TEST(LevenbergMarquardt, GeodesicAccelerationReachesTheSameRoot) {
  const reference::MghCase c = reference::mgh_case(1, 2);  // Rosenbrock: a curved valley
  Eigen::VectorXd plain_x = c.start(10.0), fast_x = c.start(10.0);
  const Summary plain = Lm({}, strict()).solve(to_fixed_point(c.problem), plain_x);
  const Summary fast =
      Lm({.geodesic_acceleration = true}, strict()).solve(to_fixed_point(c.problem), fast_x);
  ASSERT_TRUE(plain.converged()) << plain.full_report();
  ASSERT_TRUE(fast.converged()) << fast.full_report();
  EXPECT_LT((plain_x - fast_x).norm(), 1e-10);
}

TEST(LevenbergMarquardt, GeodesicAccelerationIsAThirdOrderCorrection) {
  // F(x) = eˣ − 2 from x0 = 1: the undamped step is Newton's; with the acceleration a/2 (the
  // curvature F'' v²) it is Chebyshev's third-order method, so fewer iterations reach 1e-14.
  const auto problem = to_fixed_point(RootProblem<1>::with_autodiff([](const auto& x) {
    using std::exp;
    using T = typename std::decay_t<decltype(x)>::Scalar;
    Eigen::Matrix<T, 1, 1> f;
    f[0] = exp(x[0]) - 2.0;
    return f;
  }));
  SolverOptions o = test::tolerance(1e-300);
  o.stop.residual_tolerance = 1e-14;
  Vector<1> plain_x(1.0), fast_x(1.0);
  const Summary plain = LevenbergMarquardtEngine<1>({}, o).solve(problem, plain_x);
  const Summary fast =
      LevenbergMarquardtEngine<1>({.geodesic_acceleration = true}, o).solve(problem, fast_x);
  ASSERT_TRUE(plain.converged()) << plain.full_report();
  ASSERT_TRUE(fast.converged()) << fast.full_report();
  EXPECT_NEAR(fast_x[0], std::log(2.0), 1e-14);
  EXPECT_LT(fast.iterations, plain.iterations) << plain.iterations;
}

TEST(LevenbergMarquardt, MoresScalingAndTheGradientTest) {
  // Moré's scaling solves the helical valley too.
  const reference::MghCase c = reference::mgh_case(5, 3);
  Eigen::VectorXd x = c.start(10.0);
  const Summary s =
      Lm({.scale_by_jacobian_columns = true}, strict()).solve(to_fixed_point(c.problem), x);
  EXPECT_TRUE(s.converged()) << s.full_report();
  // A loose gtol ends a least-squares fit at once, by name.
  const ExponentialFit fit(0.02);
  Eigen::VectorXd p = Eigen::Vector3d(2.0, -0.7, 0.5);
  const Summary g = Lm({.gradient_tolerance = 0.5}, strict()).solve_least_squares(fit.problem(), p);
  EXPECT_TRUE(g.converged()) << g.full_report();
  EXPECT_NE(g.message.find("gradient"), std::string::npos) << g.message;
}

TEST(LevenbergMarquardt, FiniteDifferenceJacobiansStayWithinTheBudget) {
  const ExponentialFit fit(0.02);
  const RootProblem<Dynamic, Dynamic> with_ad = fit.problem();
  const auto no_jacobian = RootProblem<Dynamic, Dynamic>::from_map(
      [&with_ad](const Eigen::VectorXd& p, Eigen::VectorXd& r) { with_ad.evaluate(p, r); }, 3, 12);
  for (const int budget : {1, 6, 7, 8, 14, 20}) {
    SolverOptions o = strict();
    o.stop.max_evaluations = budget;
    Eigen::VectorXd p = Eigen::Vector3d(1.0, -0.1, 0.0);
    const Summary s = Lm({}, o).solve_least_squares(no_jacobian, p);  // central: 6 per Jacobian
    EXPECT_LE(s.function_evaluations, budget) << s.full_report();
    EXPECT_EQ(s.status, Status::kMaxEvaluations) << budget;
  }
}

TEST(LevenbergMarquardt, FixedAndDynamicSizesAgree) {
  const reference::MghCase c = reference::mgh_case(5, 3);
  const auto dynamic = to_fixed_point(c.problem);
  const auto fixed = FixedPointProblem<3>::with_jacobian(
      [&dynamic](const Vector<3>& x, Vector<3>& g) {
        Eigen::VectorXd gx(3);
        dynamic.evaluate(x, gx);
        g = gx;
      },
      [&dynamic](const Vector<3>& x, Matrix<3, 3>& j) {
        Eigen::MatrixXd jx(3, 3);
        dynamic.jacobian(x, jx);
        j = jx;
      });
  Eigen::VectorXd xd = c.start(1.0);
  Vector<3> xf = c.start(1.0);
  const Summary sd = Lm({}, strict()).solve(dynamic, xd);
  const Summary sf = LevenbergMarquardtEngine<3>({}, strict()).solve(fixed, xf);
  ASSERT_TRUE(sd.converged()) << sd.full_report();
  EXPECT_EQ(sd.iterations, sf.iterations);
  EXPECT_EQ(sd.function_evaluations, sf.function_evaluations);
  EXPECT_LT((xd - Eigen::VectorXd(xf)).norm(), 1e-14);
}

TEST(LevenbergMarquardt, BadInputIsRefusedByName) {
  EXPECT_NE(
      test::message_of([] { Lm({.initial_radius_factor = 0.0}); }).find("initial_radius_factor"),
      std::string::npos);
  EXPECT_NE(test::message_of([] { Lm({.function_tolerance = -1.0}); }).find("function_tolerance"),
            std::string::npos);
  EXPECT_NE(
      test::message_of([] { Lm({.acceleration_ratio = std::nan("")}); }).find("acceleration_ratio"),
      std::string::npos);
  // Fewer residuals than unknowns.
  const auto under = RootProblem<Dynamic, Dynamic>::from_map(
      [](const Eigen::VectorXd& x, Eigen::VectorXd& f) {
        f = Eigen::VectorXd::Constant(1, x.sum());
      },
      2, 1);
  Lm lm;
  Eigen::VectorXd x = Eigen::Vector2d(1.0, 1.0);
  EXPECT_NE(test::message_of([&] { lm.solve_least_squares(under, x); }).find("at least as many"),
            std::string::npos);
  // A residual of the wrong size.
  const auto wrong = RootProblem<Dynamic, Dynamic>::from_map(
      [](const Eigen::VectorXd&, Eigen::VectorXd& f) { f = Eigen::VectorXd::Zero(2); }, 2, 3);
  EXPECT_NE(test::message_of([&] { lm.solve_least_squares(wrong, x); }).find("size 2"),
            std::string::npos);
  auto& registry = EngineRegistry<>::global();
  EXPECT_EQ(registry.create("levenberg-marquardt:scale=none,geodesic=1")->name(),
            "levenberg-marquardt");
  EXPECT_NE(
      test::message_of([&] { registry.create("levenberg-marquardt:scale=more"); }).find("scale"),
      std::string::npos);
  EXPECT_TRUE(registry.create("levenberg-marquardt")->least_squares());
}

TEST(LevenbergMarquardt, NonFiniteStartAndBudget) {
  const auto nan_everywhere = FixedPointProblem<2>::from_map(
      [](const Vector<2>&, Vector<2>& g) { g.setConstant(std::nan("")); });
  Vector<2> x(1.0, 1.0);
  const Summary s = LevenbergMarquardtEngine<2>({}, strict()).solve(nan_everywhere, x);
  EXPECT_EQ(s.status, Status::kNonFinite);
  EXPECT_EQ(x, Vector<2>(1.0, 1.0));

  const reference::MghCase c = reference::mgh_case(1, 2);
  SolverOptions o = strict();
  o.stop.max_evaluations = 3;  // it needs 6
  Eigen::VectorXd y = c.start(100.0);
  const Summary b = Lm({}, o).solve(to_fixed_point(c.problem), y);
  EXPECT_EQ(b.status, Status::kMaxEvaluations) << b.full_report();
  EXPECT_LE(b.function_evaluations, 3);
}

}  // namespace
}  // namespace nlobs
