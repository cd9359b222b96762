// Strict bounds (BoxBounds::strict_lower/strict_upper: lower < x, KINSOL's constraints ±2) on
// every Newton-type engine: a problem whose F is undefined on its bound (ln c) solved without
// one evaluation on or past it — AD and finite-difference Jacobians, scaled and unscaled — where
// the closed box evaluates ln 0; a root past a strict bound ends blocked_by_bound naming it; bad
// strict bounds refused with the engine's box kept; the suite judges a point on a strict bound
// outside. Problems nlobs does not ship.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "nlobs/reference/problem_suite.hpp"
#include "nlobs/registry/problem_sets.hpp"
#include "nlobs/registry/problem_sets/bounded_set.hpp"
#include "nlobs/solvers/builtin_engines.hpp"
#include "test_support.hpp"

namespace nlobs {
namespace {

SolverOptions tight() {
  SolverOptions o = test::tolerance(1e-12);
  o.stop.residual_tolerance = 1e-10;
  o.stop.max_evaluations = 5000;
  return o;
}

// Three species in equilibrium: ln cᵢ + cᵢ + 0.1 Σ_{j≠i} cⱼ = aᵢ, defined for c > 0 only. The
// roots are small (c₀ ≈ 6e-3): from c = 5 a Newton step lands far below zero.
constexpr int kSpecies = 3;
RootProblem<Dynamic> equilibrium() {
  return RootProblem<Dynamic>::with_autodiff(
      [](const auto& c, auto& out) {
        using std::log;
        const double a[kSpecies] = {-5.0, -2.0, 1.0};
        for (int i = 0; i < kSpecies; ++i) {
          out[i] = log(c[i]) + c[i] - a[i];
          for (int j = 0; j < kSpecies; ++j) {
            if (j != i) out[i] += 0.1 * c[j];
          }
        }
      },
      kSpecies, kSpecies);
}

BoxBounds positive(bool strict) {
  BoxBounds b{Eigen::VectorXd::Zero(kSpecies), Eigen::VectorXd()};
  if (strict) b.strict_lower = StrictBounds::Constant(kSpecies, true);
  return b;
}

// G(x) = x + F(x), counting the points with some cᵢ ≤ 0; with_jacobian = false leaves the
// Jacobian to the engines' differences.
FixedPointProblem<Dynamic> counting(const RootProblem<Dynamic>& f, int& on_or_past_bound,
                                    bool with_jacobian) {
  auto g = [&f, &on_or_past_bound](const Eigen::VectorXd& x, Eigen::VectorXd& out) {
    if ((x.array() <= 0.0).any()) ++on_or_past_bound;
    out.resize(x.size());
    f.evaluate(x, out);
    out += x;
  };
  if (!with_jacobian) return FixedPointProblem<Dynamic>::from_map(g, f.size());
  auto dg = [&f, &on_or_past_bound](const Eigen::VectorXd& x, Eigen::MatrixXd& jac) {
    if ((x.array() <= 0.0).any()) ++on_or_past_bound;
    f.jacobian(x, jac);
    jac += Eigen::MatrixXd::Identity(x.size(), x.size());
  };
  return FixedPointProblem<Dynamic>::with_jacobian(g, dg, f.size());
}

TEST(StrictBounds, EveryEngineSolvesWithoutEvaluatingOnTheBound) {
  const RootProblem<Dynamic> f = equilibrium();
  for (const bool scaled : {false, true}) {
    for (const bool with_jacobian : {true, false}) {
      for (const std::string& spec : test::kJacobianEngineSpecs) {
        // The scaled flow of pseudo-transient is D_u = 100 times slower in c₀ (docs/solvers.md,
        // "Scaling"): 2985 iterations with AD, past the budget with differences.
        if (scaled && spec == "pseudo-transient") continue;
        const std::string run =
            spec + (with_jacobian ? " (AD)" : " (differences)") + (scaled ? " scaled" : "");
        auto engine = EngineRegistry<Dynamic>::global().create(spec, tight());
        engine->set_bounds(positive(true));
        // D_u of the roots' orders: the scaled solve's D_u⁻¹ x̃ must stay off the bound too.
        if (scaled) engine->set_scaling({Eigen::Vector3d(100.0, 10.0, 1.0), Eigen::VectorXd()});
        int on_bound = 0;
        Eigen::VectorXd c = Eigen::VectorXd::Constant(kSpecies, 5.0);
        const Summary s = engine->solve(counting(f, on_bound, with_jacobian), c);
        EXPECT_EQ(on_bound, 0) << run;
        EXPECT_TRUE(s.usable()) << run << ": " << s.brief_report() << " " << s.message;
        EXPECT_TRUE((c.array() > 0.0).all()) << run << ": " << c.transpose();
        Eigen::VectorXd fc(kSpecies);
        f.evaluate(c, fc);
        EXPECT_LT(fc.norm(), 1e-8) << run << ": " << c.transpose();
      }
    }
  }
}

// What the strict side prevents: the closed box [0, ∞) lets Newton's first step land on c = 0,
// where ln 0 = −∞.
TEST(StrictBounds, TheClosedBoxEvaluatesOnTheBoundWhereTheStrictOneDoesNot) {
  const RootProblem<Dynamic> f = equilibrium();
  for (const bool strict : {false, true}) {
    auto engine = EngineRegistry<Dynamic>::global().create("newton", tight());
    engine->set_bounds(positive(strict));
    int on_bound = 0;
    Eigen::VectorXd c = Eigen::VectorXd::Constant(kSpecies, 5.0);
    const Summary s = engine->solve(counting(f, on_bound, true), c);
    if (strict) {
      EXPECT_EQ(on_bound, 0);
      EXPECT_TRUE(s.converged()) << s.brief_report();
    } else {
      EXPECT_GT(on_bound, 0) << s.brief_report();
    }
  }
}

TEST(StrictBounds, ARootPastAStrictBoundEndsBlockedByBoundNamingIt) {
  // F(x) = (s(u + 1 + 0.1 u²), x₂ − 2), u = s(x₁ − b), with b = 0 strict lower (s = 1) or b = 10
  // strict upper (s = −1): the root lies 1.13 past the bound, and −F (the flow) points there; steps
  // towards it stop short of b, each closer, until the room left is negligible. With the Jacobian
  // and with differences (whose points near the bound are one-sided, at most half the room out).
  for (const bool upper : {false, true}) {
    const double b = upper ? 10.0 : 0.0, sign = upper ? -1.0 : 1.0;
    const auto f = RootProblem<2>::with_autodiff([b, sign](const auto& x) {
      using T = typename std::decay_t<decltype(x)>::Scalar;
      Eigen::Matrix<T, 2, 1> out;
      const T u = sign * (x[0] - b);
      out << sign * (u + 1.0 + 0.1 * u * u), x[1] - 2.0;
      return out;
    });
    for (const bool with_jacobian : {true, false}) {
      for (const std::string& spec : test::kJacobianEngineSpecs) {
        const std::string run =
            spec + (upper ? " upper" : " lower") + (with_jacobian ? " (AD)" : " (differences)");
        auto engine = EngineRegistry<2>::global().create(spec, tight());
        BoxBounds box{Eigen::Vector2d(-10.0, -10.0), Eigen::Vector2d(10.0, 10.0)};
        box.lower[0] = upper ? -10.0 : 0.0;
        StrictBounds strict = StrictBounds::Constant(2, false);
        strict[0] = true;
        (upper ? box.strict_upper : box.strict_lower) = strict;
        engine->set_bounds(box);
        int on_bound = 0;
        auto g_map = [&](const Vector<2>& x, Vector<2>& out) {
          if (sign * (x[0] - b) <= 0.0) ++on_bound;
          f.evaluate(x, out);
          out += x;
        };
        const auto g = with_jacobian ? FixedPointProblem<2>::with_jacobian(
                                           g_map,
                                           [&](const Vector<2>& x, Matrix<2, 2>& jac) {
                                             if (sign * (x[0] - b) <= 0.0) ++on_bound;
                                             f.jacobian(x, jac);
                                             jac += Matrix<2, 2>::Identity();
                                           })
                                     : FixedPointProblem<2>::from_map(g_map);
        Vector<2> x(upper ? 7.0 : 3.0, 0.0);
        const Summary s = engine->solve(g, x);
        EXPECT_EQ(on_bound, 0) << run;
        EXPECT_GT(sign * (x[0] - b), 0.0) << run;
        EXPECT_LT(sign * (x[0] - b), 1e-4) << run;
        EXPECT_FALSE(s.usable()) << run;
        // Once x₁ is held, pseudo-transient's flow takes ~700 small steps to settle x₂ (as in a
        // closed box; auto runs it last): switched evolution relaxation grows δ with ‖F‖⁻¹,
        // and ‖F‖ is the held F₁ ≈ 1. With differences (5 evaluations a step) that may spend
        // the budget first. The others stop within a few dozen evaluations.
        const bool flow = spec == "pseudo-transient" || spec == "auto";
        if (flow && !with_jacobian && s.status == Status::kMaxEvaluations) continue;
        EXPECT_EQ(s.status, Status::kBlockedByBound)
            << run << ": " << s.brief_report() << " at " << x.transpose();
        const std::string named =
            std::string("next to its strict ") + (upper ? "upper bound 10" : "lower bound 0");
        EXPECT_NE(s.message.find(named), std::string::npos) << run << ": " << s.message;
        EXPECT_LE(s.function_evaluations, flow ? (with_jacobian ? 1000 : 5000) : 300) << run;
      }
    }
  }
}

TEST(StrictBounds, AComponentNearAStrictBoundIsNotHeldByALargeGradient) {
  // F(x) = 10⁴ (x − 5·10⁻⁴) on x > 0 from x = 10⁻³: the root lies inside, half the room away, and
  // −∇φ = −10⁸ (x − 5·10⁻⁴) is large. The room (10⁻³) is no reason to freeze x or to call the
  // run blocked: a gradient's entries are not lengths of x.
  const auto f = RootProblem<1>::with_autodiff([](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    Eigen::Matrix<T, 1, 1> out;
    out << 1e4 * (x[0] - 5e-4);
    return out;
  });
  for (const std::string& spec : test::kJacobianEngineSpecs) {
    auto engine = EngineRegistry<1>::global().create(spec, tight());
    BoxBounds box{Vector<1>(0.0), Eigen::VectorXd()};
    box.strict_lower = StrictBounds::Constant(1, true);
    engine->set_bounds(box);
    Vector<1> x(1e-3);
    const Summary s = engine->solve(to_fixed_point(f), x);
    EXPECT_TRUE(s.usable()) << spec << ": " << s.brief_report() << " " << s.message;
    EXPECT_NEAR(x[0], 5e-4, 1e-12) << spec;
  }
}

// A plugin engine that keeps x in a closed box and does not override accepts_strict_bounds().
class ClosedBoxPlugin final : public Engine<Dynamic> {
 public:
  ClosedBoxPlugin() : Engine<Dynamic>(SolverOptions{}) {}
  std::string_view name() const override { return "closed-box-plugin"; }
  bool accepts_bounds() const override { return true; }
  Summary solve(const FixedPointProblem<Dynamic>&, Eigen::VectorXd&) override { return {}; }
};

TEST(StrictBounds, BadStrictBoundsAreRefusedAndTheEngineKeepsItsBox) {
  auto engine = EngineRegistry<Dynamic>::global().create("newton", tight());
  engine->set_bounds(positive(true));
  BoxBounds wrong_size = positive(true);
  wrong_size.strict_lower = StrictBounds::Constant(2, true);
  EXPECT_NE(test::message_of([&] {
              engine->set_bounds(wrong_size);
            }).find("strict_lower has 2 flags, lower_bounds 3 bounds"),
            std::string::npos);
  BoxBounds without_bound;
  without_bound.strict_upper = StrictBounds::Constant(3, true);
  EXPECT_NE(test::message_of([&] {
              engine->set_bounds(without_bound);
            }).find("strict_upper has 3 flags, upper_bounds 0 bounds"),
            std::string::npos);
  BoxBounds empty_interior{Eigen::Vector3d(0.0, 1.0, 0.0), Eigen::Vector3d(1.0, 1.0, 1.0)};
  empty_interior.strict_upper = StrictBounds::Constant(3, false);
  empty_interior.strict_upper[1] = true;
  EXPECT_NE(test::message_of([&] {
              engine->set_bounds(empty_interior);
            }).find("lower_bounds[1] = upper_bounds[1] = 1 with a strict side"),
            std::string::npos);
  ASSERT_EQ(engine->bounds().strict_lower.size(), kSpecies);  // the box it had
  EXPECT_TRUE(engine->bounds().strict_lower.all());

  // A start on a strict bound is refused at solve, naming the component, scaled or not.
  const FixedPointProblem<Dynamic> g = to_fixed_point(equilibrium());
  for (const bool scaled : {false, true}) {
    if (scaled) engine->set_scaling({Eigen::Vector3d(100.0, 10.0, 1.0), Eigen::VectorXd()});
    Eigen::VectorXd on_bound(3);
    on_bound << 1.0, 0.0, 1.0;
    const std::string message = test::message_of([&] { engine->solve(g, on_bound); });
    EXPECT_NE(message.find("x0[1] = 0 lies on its strict lower bound"), std::string::npos)
        << message;
    EXPECT_EQ(on_bound[1], 0.0);
  }

  // Ceres' and NLopt's boxes are closed: they refuse strict sides and keep their box.
  for (const char* spec : {"ceres", "nlopt:LD_SLSQP"}) {
    auto closed_only = EngineRegistry<Dynamic>::global().create(spec, tight());
    EXPECT_TRUE(closed_only->accepts_bounds()) << spec;
    EXPECT_FALSE(closed_only->accepts_strict_bounds()) << spec;
    EXPECT_NE(test::message_of([&] {
                closed_only->set_bounds(positive(true));
              }).find("keeps x in a closed box only"),
              std::string::npos)
        << spec;
    EXPECT_TRUE(closed_only->bounds().empty()) << spec;
  }
  // An engine that keeps a box but does not say it takes strict sides refuses them.
  EXPECT_NE(test::message_of([] {
              ClosedBoxPlugin plugin;
              plugin.set_bounds(positive(true));
            }).find("closed-box-plugin keeps x in a closed box only"),
            std::string::npos);
  EXPECT_TRUE(EngineRegistry<Dynamic>::global().create("auto")->accepts_strict_bounds());
  EXPECT_FALSE(
      EngineRegistry<Dynamic>::global().create("auto:order=newton/ceres")->accepts_strict_bounds());
}

TEST(StrictBounds, ProblemSetsCarryThemAndTheSuiteJudgesTheBoundOutside) {
  TestProblem p{.name = "equilibrium",
                .residual = equilibrium(),
                .starts = {{"fives", Eigen::VectorXd::Constant(kSpecies, 5.0)}}};
  p.lower = Eigen::VectorXd::Zero(kSpecies);
  p.strict_lower = StrictBounds::Constant(kSpecies, true);
  EXPECT_TRUE(p.first_outside_bounds(Eigen::Vector3d(1.0, 1e-300, 1.0)) == std::nullopt);
  EXPECT_EQ(p.first_outside_bounds(Eigen::Vector3d(1.0, 0.0, 1.0)), Index{1});
  ProblemSetEntry set;
  set.name = "strict-test";
  set.problems = [p] { return std::vector<TestProblem>{p}; };
  const std::vector<TestProblem> problems = build_problem_set(set);
  // Ceres and NLopt get a closed box √ε inside the strict one (one ulp inside, NLopt's SLSQP
  // jumped to c = 5e-324, where ∂ ln c = 1/c is infinite, and stopped non_finite).
  const auto rows = reference::run_suite(
      set, problems, {"newton", "auto", "minpack:hybrj", "ceres", "nlopt:LD_SLSQP"});
  ASSERT_EQ(rows.size(), 5U);
  for (const reference::SuiteRow& row : rows) {
    if (row.solver == "minpack:hybrj") continue;  // unbounded, judged alike
    EXPECT_TRUE(row.solved) << row.solver << ": " << row.status << " " << row.message;
  }

  // A start on a strict bound, or strict flags that do not fit, are the set's errors.
  ProblemSetEntry bad = set;
  bad.problems = [p] {
    TestProblem q = p;
    q.starts = {{"on-bound", Eigen::Vector3d(1.0, 0.0, 1.0)}};
    return std::vector<TestProblem>{q};
  };
  EXPECT_NE(test::message_of([&] { build_problem_set(bad); }).find("on-bound"), std::string::npos);
  bad.problems = [p] {
    TestProblem q = p;
    q.strict_lower = StrictBounds::Constant(2, true);
    return std::vector<TestProblem>{q};
  };
  EXPECT_NE(test::message_of([&] {
              build_problem_set(bad);
            }).find("strict_lower has 2 flags, lower 3 bounds"),
            std::string::npos);
}

TEST(StrictBounds, ShachamsReactorOnItsOpenInterval) {
  // x < 0.8 strictly: at 0.8 the log's argument divides by zero. From 0.5 Newton's step lands at
  // 2.0; it stops at 0.8 − 0.01 · 0.3 and converges to 0.757396.
  const std::vector<TestProblem> problems = build_problem_set(bounded_problem_set());
  const TestProblem& p = problems.back();
  ASSERT_EQ(p.name, "shacham-cstr");
  ASSERT_EQ(p.strict_upper.size(), 1);
  EXPECT_TRUE(p.strict_upper[0]);
  NewtonEngine<> newton({}, tight());
  newton.set_bounds(p.bounds());
  int at_or_past = 0;
  const auto f = p.residual;
  const auto g = FixedPointProblem<Dynamic>::with_jacobian(
      [&](const Eigen::VectorXd& x, Eigen::VectorXd& out) {
        if (x[0] >= 0.8) ++at_or_past;
        out.resize(1);
        f.evaluate(x, out);
        out += x;
      },
      [&](const Eigen::VectorXd& x, Eigen::MatrixXd& jac) {
        f.jacobian(x, jac);
        jac(0, 0) += 1.0;
      },
      1);
  Eigen::VectorXd x = Eigen::VectorXd::Constant(1, 0.5);
  const Summary s = newton.solve(g, x);
  EXPECT_TRUE(s.converged()) << s.brief_report();
  EXPECT_NEAR(x[0], 0.7573962462537539, 1e-9);
  EXPECT_EQ(at_or_past, 0);
}

}  // namespace
}  // namespace nlobs
