// KINSOL's scaling (u_scale, f_scale) in the Newton-type engines (issue 39): a system that can be
// solved only in the scaled norm — its first equation is 1e12 times the second, so its rounding
// floor in ‖F‖∞ is about 2e-4 — solved by every Newton-type engine and by KINSOL given the same
// scales, and by neither without them; the transformation checked against the unscaled run (Newton
// is affine invariant: the same iterates); bounds, traces, the relative step test and misuse.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "nlobs/reference/kinsol_solver.hpp"
#include "nlobs/solvers/engine_registry.hpp"
#include "nlobs/solvers/fixed_point_engines.hpp"
#include "nlobs/solvers/levenberg_marquardt_engine.hpp"
#include "nlobs/solvers/newton_engine.hpp"
#include "nlobs/solvers/root_adapter.hpp"
#include "nlobs/solvers/stop_monitor.hpp"
#include "test_support.hpp"

namespace nlobs {
namespace {

// F₀ = 1e12 (x₀² − 2) (a heat balance in W), F₁ = x₁² − x₀ (a fraction); root (√2, 2^¼).
constexpr double kBig = 1e12;
template <typename V, typename R>
void heat_balance(const V& x, R& f) {
  f[0] = kBig * (x[0] * x[0] - 2.0);
  f[1] = x[1] * x[1] - x[0];
}
const Eigen::Vector2d kRoot(std::sqrt(2.0), std::pow(2.0, 0.25));
const Eigen::Vector2d kStart(1.5, 1.3);
const Eigen::VectorXd kFScale = Eigen::Vector2d(1.0 / kBig, 1.0);

FixedPointProblem<Dynamic> heat_problem() {
  return to_fixed_point<Dynamic>(RootProblem<Dynamic>::with_autodiff(
      [](const auto& x, auto& f) { heat_balance(x, f); }, 2, 2));
}

SolverOptions tight() {
  SolverOptions o;
  o.stop.step_tolerance.reset();  // the residual decides, as KINSOL's fnormtol
  o.stop.residual_tolerance = 1e-10;
  o.stop.max_evaluations = 2000;
  return o;
}

// ‖D_f F(x)‖∞ at x.
double scaled_residual(const Eigen::VectorXd& x) {
  Eigen::Vector2d f;
  heat_balance(x, f);
  return f.cwiseProduct(kFScale).lpNorm<Eigen::Infinity>();
}

TEST(Scaling, EveryNewtonTypeEngineSolvesInTheScaledNormAndNoneWithout) {
  const auto g = heat_problem();
  for (const std::string& spec : test::kJacobianEngineSpecs) {
    SCOPED_TRACE(spec);
    auto engine = EngineRegistry<Dynamic>::global().create(spec, tight());
    ASSERT_TRUE(engine->accepts_scaling());
    Eigen::VectorXd x = kStart;
    const Summary plain = engine->solve(g, x);
    // Unscaled: ‖F‖∞ cannot go below ~1e12 · ε ≈ 2e-4, far above 1e-10 and the acceptance 1e-6.
    EXPECT_FALSE(plain.converged()) << plain.brief_report();
    EXPECT_FALSE(plain.usable()) << plain.brief_report();

    engine->set_scaling({{}, kFScale});
    x = kStart;
    const Summary scaled = engine->solve(g, x);
    EXPECT_TRUE(scaled.converged()) << scaled.brief_report();
    EXPECT_TRUE(scaled.usable());
    EXPECT_LT((x - kRoot).lpNorm<Eigen::Infinity>(), 1e-12);  // x in the problem's variables
    // The summary's residual is the scaled one, at the returned point.
    EXPECT_LE(scaled.residual_norm, 1e-10);
    EXPECT_NEAR(scaled.residual_norm, scaled_residual(x), 1e-12);
    // Removing the scaling gives the unscaled engine back.
    engine->set_scaling({});
    x = kStart;
    EXPECT_FALSE(engine->solve(g, x).converged());
  }
}

// KINSOL (its Newton with line search, dense) given the same f_scale: converged, at the same root,
// in as many Newton iterations as ours; without it, KINSOL cannot meet fnormtol either.
TEST(Scaling, ScaledNewtonMatchesKinsolOnTheScaledProblem) {
  const auto f = [](const Eigen::VectorXd& x, Eigen::VectorXd& out) {
    out.resize(2);
    heat_balance(x, out);
  };
  const auto j = [](const Eigen::VectorXd& x, Eigen::MatrixXd& out) {
    out.resize(2, 2);
    out << 2.0 * kBig * x[0], 0.0, -1.0, 2.0 * x[1];
  };
  reference::KinsolOptions ko;
  ko.strategy = reference::KinsolStrategy::kNewtonLineSearch;
  ko.tolerance = 1e-10;
  Eigen::VectorXd u = kStart;
  const reference::KinsolResult plain = reference::KinsolSolver(2, ko, f, j).solve(u);
  EXPECT_FALSE(plain.success) << plain.flag_name << " " << plain.reason;
  ko.f_scale = kFScale;
  u = kStart;
  const reference::KinsolResult kinsol = reference::KinsolSolver(2, ko, f, j).solve(u);
  ASSERT_TRUE(kinsol.success) << kinsol.flag_name << " " << kinsol.reason;
  EXPECT_LT((u - kRoot).lpNorm<Eigen::Infinity>(), 1e-12);

  NewtonEngine<Dynamic> newton(NewtonOptions{.line_search = true}, tight());
  newton.set_scaling({{}, kFScale});
  Eigen::VectorXd x = kStart;
  const Summary s = newton.solve(heat_problem(), x);
  ASSERT_TRUE(s.converged()) << s.brief_report();
  EXPECT_LT((x - u).lpNorm<Eigen::Infinity>(), 1e-12);
  // Full Newton steps from a start this close, for both: the same count (KINSOL counts the
  // iterations it made, ours too).
  EXPECT_EQ(s.iterations, kinsol.iterations) << s.brief_report();
}

// Newton's iterates do not depend on the scaling (affine invariance): any D_u, D_f give the same
// points and the same count when the residual test is met at once by both — a wrong Jacobian
// transformation would lose quadratic convergence and show here. With a user's Jacobian, with
// AD, and differenced in the scaled variables.
TEST(Scaling, NewtonsIteratesAreTheSameInAnyScaling) {
  const auto f = [](const auto& x, auto& out) {
    using std::exp;
    out[0] = exp(x[0]) - 2.0 * x[1];
    out[1] = x[0] * x[1] - 1.5 + x[2];
    out[2] = x[2] * x[2] * x[2] - x[0];
  };
  const auto by_ad = to_fixed_point<Dynamic>(RootProblem<Dynamic>::with_autodiff(f, 3, 3));
  const auto by_fd = to_fixed_point<Dynamic>(RootProblem<Dynamic>::from_map(
      [f](const Eigen::VectorXd& x, Eigen::VectorXd& out) { f(x, out); }, 3, 3));
  const Eigen::Vector3d start(0.5, 1.0, 0.7);
  const Scaling odd{Eigen::Vector3d(1e3, 0.5, 7.0), Eigen::Vector3d(2.0, 1e-4, 30.0)};
  for (const auto* problem : {&by_ad, &by_fd}) {
    SolverOptions o;
    o.stop.step_tolerance.reset();
    o.stop.residual_tolerance = 1e-300;  // never met: every run takes max_iterations steps
    o.stop.max_iterations = 6;
    o.stop.stagnation_patience = 0;
    o.record_trace = true;
    NewtonEngine<Dynamic> plain({}, o), scaled({}, o);
    scaled.set_scaling(odd);
    Eigen::VectorXd x = start, y = start;
    const Summary a = plain.solve(*problem, x);
    const Summary b = scaled.solve(*problem, y);
    ASSERT_EQ(a.trace.size(), b.trace.size());
    for (std::size_t k = 0; k < a.trace.size(); ++k) {
      // The trace's points in the problem's variables.
      EXPECT_LT((a.trace[k].x - b.trace[k].x).lpNorm<Eigen::Infinity>(),
                problem == &by_ad ? 1e-12 : 1e-6)
          << k;
    }
    EXPECT_LT((x - y).lpNorm<Eigen::Infinity>(), 1e-12);
    EXPECT_EQ(y, b.trace.back().x);
    // The step the summary reports is ‖D_u Δx‖∞ in the scaled run.
    EXPECT_NE(a.step_norm, b.step_norm);
  }
}

// In a box, a scaled engine keeps every evaluation inside the problem's own box (its box in x̃ is
// D_u times it): x² = 4 on [0, 10] from 9, u_scale 0.25 (x̃ in [0, 2.5], as KINSOL's D_u x ~ 1
// asks), differences included. (pseudo-transient follows ẋ = −D_u⁻¹ D_f F: with u_scale 1e3 its
// flow is a thousand times slower in x and spends its budget, as Kelley and Keyes' scaled flow.)
TEST(Scaling, TheBoxHoldsInTheProblemsVariables) {
  double lowest = std::numeric_limits<double>::infinity(), highest = -lowest;
  const auto g = to_fixed_point<Dynamic>(RootProblem<Dynamic>::from_map(
      [&](const Eigen::VectorXd& x, Eigen::VectorXd& out) {
        lowest = std::min(lowest, x[0]);
        highest = std::max(highest, x[0]);
        out.resize(1);
        out[0] = x[0] * x[0] - 4.0;
      },
      1, 1));
  for (const std::string& spec : test::kJacobianEngineSpecs) {
    SCOPED_TRACE(spec);
    auto engine = EngineRegistry<Dynamic>::global().create(spec, tight());
    engine->set_bounds({Eigen::VectorXd::Constant(1, 0.0), Eigen::VectorXd::Constant(1, 10.0)});
    engine->set_scaling({Eigen::VectorXd::Constant(1, 0.25), {}});
    lowest = std::numeric_limits<double>::infinity();
    highest = -lowest;
    Eigen::VectorXd x = Eigen::VectorXd::Constant(1, 9.0);
    const Summary s = engine->solve(g, x);
    EXPECT_TRUE(s.usable()) << s.brief_report();
    EXPECT_NEAR(x[0], 2.0, 1e-8);
    EXPECT_GE(lowest, 0.0);
    EXPECT_LE(highest, 10.0);
    // The engine still reports the box it was given, not the scaled one.
    EXPECT_EQ(engine->bounds().upper[0], 10.0);
    // A start outside the box is refused in the problem's terms.
    x[0] = 11.0;
    try {
      engine->solve(g, x);
      ADD_FAILURE() << "accepted";
    } catch (const InvalidInput& e) {
      EXPECT_NE(std::string(e.what()).find("x0[0] = 11 lies outside the box (upper bound 10)"),
                std::string::npos)
          << e.what();
    }
  }
}

// A root on a bound, with a scale whose round trip D_u⁻¹(D_u b) rounds below b (b = 1e-4,
// D_u = 49): every evaluation and the answer stay inside the box.
TEST(Scaling, ARootOnABoundIsReachedInsideTheBox) {
  // Both ways back from x̃ round below the bound at D_u = 49: (b·d)·(1/d) and (b·d)/d.
  const double b = 1e-4, d = 49.0;
  ASSERT_LT((b * d) * (1.0 / d), b);
  ASSERT_LT((b * d) / d, b);
  double lowest = std::numeric_limits<double>::infinity();
  const auto g = to_fixed_point<Dynamic>(RootProblem<Dynamic>::with_autodiff(
      [&lowest](const auto& x, auto& f) {
        if constexpr (std::is_same_v<std::decay_t<decltype(x[0])>, double>) {
          lowest = std::min(lowest, x[0]);
        }
        f[0] = x[0] - 1e-4;
      },
      1, 1));
  // Not pseudo-transient: its flow ẋ = −D_u⁻¹ F is 49 times slower here (x̃ ≈ 25, far from the
  // order 1 a scaling should give) and spends its budget; the box is the point of this test.
  for (const std::string& spec : test::kJacobianEngineSpecs) {
    if (spec == "pseudo-transient") continue;
    SCOPED_TRACE(spec);
    auto engine = EngineRegistry<Dynamic>::global().create(spec, tight());
    engine->set_bounds({Eigen::VectorXd::Constant(1, 1e-4), Eigen::VectorXd::Constant(1, 1.0)});
    engine->set_scaling({Eigen::VectorXd::Constant(1, 49.0), {}});
    lowest = std::numeric_limits<double>::infinity();
    Eigen::VectorXd x = Eigen::VectorXd::Constant(1, 0.5);
    const Summary s = engine->solve(g, x);
    EXPECT_TRUE(s.usable()) << s.brief_report();
    EXPECT_GE(x[0], 1e-4);
    EXPECT_NEAR(x[0], 1e-4, 1e-15);
    EXPECT_GE(lowest, 1e-4);
  }
}

// F much smaller than x: F = 1e-12 (x − 1000). Formed as G(x) − x, F carries ulp(1000)/2 ≈ 6e-14
// of rounding, 0.06 once D_f = 1e12 multiplies it; the engines get F itself (to_fixed_point's
// residual form) and meet 1e-10 in the scaled norm. So does the least-squares path (a square F).
TEST(Scaling, ASmallResidualBesideALargeUnknownKeepsItsDigits) {
  const auto f = [](const auto& x, auto& out) { out[0] = 1e-12 * (x[0] - 1000.0); };
  const auto root = RootProblem<Dynamic>::with_autodiff(f, 1, 1);
  const auto g = to_fixed_point<Dynamic>(root);
  ASSERT_TRUE(g.has_residual());
  for (const std::string& spec : test::kJacobianEngineSpecs) {
    SCOPED_TRACE(spec);
    auto engine = EngineRegistry<Dynamic>::global().create(spec, tight());
    engine->set_scaling({{}, Eigen::VectorXd::Constant(1, 1e12)});
    Eigen::VectorXd x = Eigen::VectorXd::Constant(1, 900.0);
    const Summary s = engine->solve(g, x);
    EXPECT_TRUE(s.converged()) << s.brief_report();
    EXPECT_NEAR(x[0], 1000.0, 1e-9);
    x.setConstant(900.0);
    const Summary ls =
        engine->solve_least_squares(RootProblem<Dynamic, Dynamic>::with_autodiff(f, 1, 1), x);
    EXPECT_TRUE(ls.converged()) << ls.brief_report();
    EXPECT_NEAR(x[0], 1000.0, 1e-9);
  }
  // Levenberg-Marquardt's least-squares path with m > n: a scaling is refused, named.
  LevenbergMarquardtEngine<Dynamic> lm({}, tight());
  lm.set_scaling({{}, Eigen::VectorXd::Constant(2, 1.0)});
  Eigen::VectorXd x = Eigen::VectorXd::Constant(1, 1.0);
  const auto tall = RootProblem<Dynamic, Dynamic>::with_autodiff(
      [](const auto& v, auto& out) {
        out[0] = v[0] - 1.0;
        out[1] = v[0] - 1.0;
      },
      1, 2);
  EXPECT_THROW(lm.solve_least_squares(tall, x), InvalidInput);
}

// Fixed sizes: a NewtonEngine<2> and the registry's auto at N = 2 (a DynamicSizeEngine serving
// size 2, which passes the scaling and F itself on) solve the heat balance in its scaling.
TEST(Scaling, FixedSizeEnginesTakeTheScalingToo) {
  const auto g2 = to_fixed_point<2>(
      RootProblem<2, 2>::with_autodiff([](const auto& x, auto& f) { heat_balance(x, f); }));
  NewtonEngine<2> newton({}, tight());
  newton.set_scaling({{}, kFScale});
  Eigen::Vector2d x = kStart;
  EXPECT_TRUE(newton.solve(g2, x).converged());
  EXPECT_LT((x - kRoot).lpNorm<Eigen::Infinity>(), 1e-12);
  for (const char* spec : {"auto", "dogleg", "levenberg-marquardt"}) {
    auto engine = EngineRegistry<2>::global().create(spec, tight());
    engine->set_scaling({{}, kFScale});
    x = kStart;
    EXPECT_TRUE(engine->solve(g2, x).converged()) << spec;
    EXPECT_LT((x - kRoot).lpNorm<Eigen::Infinity>(), 1e-12) << spec;
  }
}

// A scaled solve whose F throws leaves the engine as it was: its box, its scaling, and the next
// solve scaled again.
TEST(Scaling, AThrowingProblemLeavesTheEngineAsItWas) {
  bool fail = true;
  const auto g = to_fixed_point<Dynamic>(RootProblem<Dynamic>::with_autodiff(
      [&fail](const auto& x, auto& f) {
        if (fail) throw std::runtime_error("the model left its domain");
        heat_balance(x, f);
      },
      2, 2));
  NewtonEngine<Dynamic> newton({}, tight());
  newton.set_bounds({Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(10.0, 10.0)});
  newton.set_scaling({Eigen::Vector2d(0.5, 2.0), kFScale});
  Eigen::VectorXd x = kStart;
  EXPECT_THROW(newton.solve(g, x), std::runtime_error);
  EXPECT_EQ(newton.bounds().upper, Eigen::VectorXd(Eigen::Vector2d(10.0, 10.0)));
  EXPECT_EQ(newton.scaling().u_scale, Eigen::VectorXd(Eigen::Vector2d(0.5, 2.0)));
  fail = false;
  x = kStart;
  const Summary s = newton.solve(g, x);
  EXPECT_TRUE(s.converged()) << s.brief_report();
  EXPECT_LT((x - kRoot).lpNorm<Eigen::Infinity>(), 1e-12);
}

TEST(Scaling, MisuseIsRefusedNamingWhatIsWrong) {
  const auto refused = [](Engine<Dynamic>& e, Scaling s) -> std::string {
    try {
      e.set_scaling(std::move(s));
    } catch (const InvalidInput& err) {
      return err.what();
    }
    return "<accepted>";
  };
  PicardEngine<Dynamic> picard;
  EXPECT_NE(
      refused(picard, {{}, Eigen::Vector2d(1.0, 2.0)}).find("picard does not accept a scaling"),
      std::string::npos);
  EXPECT_EQ(refused(picard, {}), "<accepted>");  // no scaling: nothing to refuse
  NewtonEngine<Dynamic> newton;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_NE(refused(newton, {Eigen::Vector2d(1.0, 0.0), {}}).find("u_scale[1] = 0 is not finite"),
            std::string::npos);
  EXPECT_NE(refused(newton, {{}, Eigen::Vector2d(-1.0, 1.0)}).find("f_scale[0] = -1"),
            std::string::npos);
  EXPECT_NE(refused(newton, {{}, Eigen::Vector2d(nan, 1.0)}).find("f_scale[0] = nan"),
            std::string::npos);
  EXPECT_NE(refused(newton, {Eigen::Vector2d(inf, 1.0), {}}).find("u_scale[0] = inf"),
            std::string::npos);
  EXPECT_NE(refused(newton, {Eigen::Vector2d(1.0, 1.0), Eigen::Vector3d(1.0, 1.0, 1.0)})
                .find("u_scale and f_scale differ in size (2 vs 3)"),
            std::string::npos);
  EXPECT_TRUE(newton.scaling().empty());  // every refusal kept the engine as it was
  // A scale of another size than the problem's: refused by solve, x untouched.
  newton.set_scaling({{}, Eigen::Vector3d(1.0, 1.0, 1.0)});
  Eigen::VectorXd x = kStart;
  try {
    newton.solve(heat_problem(), x);
    FAIL() << "accepted";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("f_scale has size 3 but the problem has dimension 2"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(x, Eigen::VectorXd(kStart));
  // auto passes it to every stage; one that refuses (a user's stage list with anderson) keeps
  // every stage as it was.
  auto with_anderson = EngineRegistry<Dynamic>::global().create("auto:order=newton/anderson");
  EXPECT_FALSE(with_anderson->accepts_scaling());
  EXPECT_NE(refused(*with_anderson, {{}, kFScale}).find("does not accept a scaling"),
            std::string::npos);
}

// The relative step test: ‖Δx‖∞ / (‖x‖∞ + 1) ≤ step_tolerance, for an unknown of size 1e5.
TEST(Scaling, TheRelativeStepTestJudgesTheStepAgainstTheIterate) {
  StopCriteria c;
  c.step_tolerance = 1e-8;
  StopMonitor absolute(c, 1e5, false);
  EXPECT_FALSE(absolute.update(1e-4, std::numeric_limits<double>::quiet_NaN(), 1e5).has_value());
  c.relative_step = true;
  StopMonitor relative(c, 1e5, false);
  EXPECT_EQ(relative.update(1e-4, std::numeric_limits<double>::quiet_NaN(), 1e5),
            Status::kConverged);
  // Near 0 it is the absolute test (the + 1).
  StopMonitor near_zero(c, 0.0, false);
  EXPECT_FALSE(near_zero.update(1e-7, std::numeric_limits<double>::quiet_NaN(), 0.0).has_value());
  // A step cut short by the engine is not judged, relative or not.
  StopMonitor cut(c, 1e5, false);
  EXPECT_FALSE(
      cut.update(1e-4, std::numeric_limits<double>::quiet_NaN(), 1e5, /*step_may_converge=*/false)
          .has_value());
}

}  // namespace
}  // namespace nlobs
