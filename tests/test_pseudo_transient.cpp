// Pseudo-transient continuation and Newton's trust-region globalisation: a start from which
// Newton diverges, a root that is unstable for the flow (named failure, no wrong answer), a model
// that leaves its domain, NaN everywhere, the budget, bad options.
#include <gtest/gtest.h>

#include <cmath>

#include "nlobs/solvers/builtin_engines.hpp"
#include "test_support.hpp"

namespace nlobs {
namespace {

using test::strict;

template <typename F>
FixedPointProblem<1> scalar_root(F f) {
  return to_fixed_point(RootProblem<1>::with_autodiff([f](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    Eigen::Matrix<T, 1, 1> r;
    r[0] = f(x[0]);
    return r;
  }));
}

const auto kAtan = [](const auto& x) {
  using std::atan;
  return atan(x);
};
const auto kLogPlus5 = [](const auto& x) {
  using std::log;
  return log(x) + 5.0;
};

TEST(PseudoTransient, FollowsTheFlowWhereNewtonDiverges) {
  // atan x from x0 = 10: Newton overshoots further each step; ẋ = −atan x flows to 0.
  const auto problem = scalar_root(kAtan);
  Vector<1> x(10.0);
  EXPECT_FALSE(NewtonEngine<1>({}, strict()).solve(problem, x).converged());
  x[0] = 10.0;
  SolverOptions o = strict();
  o.record_trace = true;
  const Summary s = PseudoTransientEngine<1>({}, o).solve(problem, x);  // the residual flow
  ASSERT_TRUE(s.converged()) << s.full_report();
  EXPECT_NEAR(x[0], 0.0, 1e-12);
  EXPECT_EQ(s.engine, "pseudo-transient");
  // The first step follows the flow (δ₀ |atan 10| ≈ 0.015, Newton's would be −144); near the
  // root δ has grown with 1/‖F‖ and the steps shrink superlinearly (measured: by 40× from one
  // step to the next; not quadratically, as long as δ⁻¹ still weighs in).
  ASSERT_GE(s.trace.size(), 4u);
  EXPECT_LT(s.trace.front().step_norm, 0.1);
  const auto& t = s.trace;
  EXPECT_LT(t[t.size() - 2].step_norm, 0.1 * t[t.size() - 3].step_norm);
}

TEST(PseudoTransient, ARootTheFlowLeavesIsNotReachedAndNotClaimed) {
  // F(x) = −x: the root 0 is unstable for the residual flow ẋ = −F = x, so that continuation
  // walks away from it; the fixed-point flow ẋ = G(x) − x = F = −x is attracted to it.
  const auto problem = scalar_root([](const auto& x) { return -x; });
  SolverOptions o = strict();
  o.stop.max_iterations = 200;
  Vector<1> x(1.0);
  const Summary s = PseudoTransientEngine<1>({.flow = PseudoTransientOptions::Flow::kResidual}, o)
                        .solve(problem, x);
  EXPECT_FALSE(s.converged()) << s.full_report();
  EXPECT_FALSE(s.usable());
  EXPECT_GT(std::abs(x[0]), 1.0);
  x[0] = 1.0;
  const Summary f = PseudoTransientEngine<1>({.flow = PseudoTransientOptions::Flow::kFixedPoint}, o)
                        .solve(problem, x);
  EXPECT_TRUE(f.converged()) << f.full_report();
  EXPECT_NEAR(x[0], 0.0, 1e-12);
}

TEST(PseudoTransient, TheFixedPointFlowSolvesWherePicardDiverges) {
  // G(x) = −2x + 3 (fixed point 1): ∂G = −2, so Picard diverges (ρ = 2 > 1), but the flow
  // ẋ = G(x) − x = −3(x − 1) is attracted to the fixed point.
  const auto problem = FixedPointProblem<1>::with_jacobian(
      [](const Vector<1>& x, Vector<1>& g) { g[0] = -2.0 * x[0] + 3.0; },
      [](const Vector<1>&, Matrix<1, 1>& j) { j(0, 0) = -2.0; });
  Vector<1> x(5.0);
  EXPECT_FALSE(PicardEngine<1>(strict()).solve(problem, x).converged());
  x[0] = 5.0;
  const Summary s =
      PseudoTransientEngine<1>({.flow = PseudoTransientOptions::Flow::kFixedPoint}, strict())
          .solve(problem, x);
  ASSERT_TRUE(s.converged()) << s.full_report();
  EXPECT_NEAR(x[0], 1.0, 1e-12);
}

TEST(PseudoTransient, ANonFiniteTrialHalvesThePseudoStep) {
  // log x + 5 from x0 = 1 with δ0 = 1e3: the first step is nearly Newton's and lands at x < 0.
  const auto problem = scalar_root(kLogPlus5);
  Vector<1> x(1.0);
  const Summary s =
      PseudoTransientEngine<1>(
          {.flow = PseudoTransientOptions::Flow::kResidual, .initial_pseudo_step = 1e3}, strict())
          .solve(problem, x);
  ASSERT_TRUE(s.converged()) << s.full_report();
  EXPECT_NEAR(x[0], std::exp(-5.0), 1e-14);
  EXPECT_GT(s.function_evaluations, s.iterations + 1);  // the rejected trials were evaluated

  const auto nowhere = FixedPointProblem<1>::with_jacobian(
      [](const Vector<1>& v, Vector<1>& g) {
        g[0] = v[0] == 1.0 ? 2.0 : std::nan("");  // finite at the start only
      },
      [](const Vector<1>&, Matrix<1, 1>& j) { j(0, 0) = 2.0; });
  x[0] = 1.0;
  const Summary n = PseudoTransientEngine<1>({}, strict()).solve(nowhere, x);
  EXPECT_EQ(n.status, Status::kNonFinite) << n.full_report();
  EXPECT_NE(n.message.find("pseudo-transient path"), std::string::npos) << n.message;
  EXPECT_EQ(x[0], 1.0);
}

TEST(PseudoTransient, BudgetAndOptions) {
  const auto no_jacobian = FixedPointProblem<2>::from_map(
      [](const Vector<2>& x, Vector<2>& g) { g = x - Vector<2>(std::atan(x[0]), x[1] - 1.0); });
  for (const int budget : {1, 4, 5, 6, 11}) {
    SolverOptions o = strict();
    o.stop.max_evaluations = budget;
    Vector<2> x(10.0, 3.0);
    const Summary s = PseudoTransientEngine<2>({}, o).solve(no_jacobian, x);
    EXPECT_LE(s.function_evaluations, budget) << s.full_report();
    EXPECT_EQ(s.status, Status::kMaxEvaluations);
  }
  EXPECT_NE(test::message_of([] {
              PseudoTransientEngine<1>({.initial_pseudo_step = 0.0});
            }).find("initial_pseudo_step"),
            std::string::npos);
  EXPECT_NE(test::message_of([] {
              PseudoTransientEngine<1>({.max_pseudo_step = 1e-3});
            }).find("max_pseudo_step"),
            std::string::npos);
  EXPECT_NE(test::message_of([] {
              PseudoTransientEngine<1>({.min_pseudo_step = 1.0});
            }).find("min_pseudo_step"),
            std::string::npos);
  for (const double growth : {0.5, 10.5, std::nan("")}) {
    EXPECT_NE(test::message_of([growth] {
                PseudoTransientEngine<1>({.pseudo_step_growth = growth});
              }).find("pseudo_step_growth (growth)"),
              std::string::npos)
        << growth;
  }
  auto& registry = EngineRegistry<>::global();
  EXPECT_EQ(registry.create("pseudo-transient:flow=residual,delta0=1e-4,delta_max=1e6")->name(),
            "pseudo-transient");
  EXPECT_NE(test::message_of([&] {
              registry.create("pseudo-transient:growth=0.9");
            }).find("must lie in [1, 10]"),
            std::string::npos);
  EXPECT_NE(test::message_of([&] { registry.create("pseudo-transient:flow=down"); }).find("flow"),
            std::string::npos);
  EXPECT_NE(test::message_of([&] {
              registry.create("pseudo-transient:delta0=-1");
            }).find("initial_pseudo_step"),
            std::string::npos);
}

// δ₀ below machine epsilon makes x + δF == x wherever |F| ≤ |x|: refused, naming the bound; a
// subnormal is a number all the same (the option's check refuses it, not the parser); a tiny δ
// was once a "converged" first step (‖p‖₂² underflowed to 0, so the step looked Newton-like).
TEST(PseudoTransient, APseudoStepTooSmallToMoveXIsRefusedAndNeverConverged) {
  auto& registry = EngineRegistry<>::global();
  for (const char* spec : {"pseudo-transient:delta0=1e-300", "pseudo-transient:delta0=4e-320",
                           "pseudo-transient:delta0=1e-17"}) {
    const std::string m = test::message_of([&] { registry.create(spec); });
    EXPECT_NE(m.find("initial_pseudo_step"), std::string::npos) << spec << ": " << m;
    EXPECT_NE(m.find("2.22e-16"), std::string::npos) << spec << ": " << m;
    EXPECT_EQ(m.find("not a finite number"), std::string::npos) << spec << ": " << m;
  }
  EXPECT_NE(test::message_of([] {
              PseudoTransientEngine<1>({.initial_pseudo_step = 1e-300, .min_pseudo_step = 1e-300});
            }).find("initial_pseudo_step"),
            std::string::npos);
  EXPECT_NE(test::message_of([] {
              PseudoTransientEngine<1>({.min_pseudo_step = 1e-300});
            }).find("min_pseudo_step"),
            std::string::npos);
  // Every positive finite value where one is meaningful: a subnormal tolerance, delta0 at the
  // floor.
  EXPECT_EQ(registry.create("newton:tol=4e-320")->name(), "newton");
  EXPECT_EQ(registry.create("pseudo-transient:delta0=2.3e-16")->name(), "pseudo-transient");
  EXPECT_NE(test::message_of([&] { registry.create("newton:tol=1e400"); }).find("not a finite"),
            std::string::npos);

  // x = 1e8, F = x − (1e8 + 10): at δ₀ = 2.3e-16 the step δF ≈ 2e-15 is below the spacing of x
  // (1.5e-8), x + p == x. Such a step is no step, and no convergence: δ doubles until x moves
  // (before: the same x at every iteration until the budget was spent). Switched evolution
  // relaxation then grows δ only as fast as ‖F‖ falls: slowly from so small a δ₀ — too slowly
  // for 0.1 % in 50 evaluations, so the progress window ends it (StopCriteria::progress_window);
  // without the window, the budget.
  const auto far = scalar_root([](const auto& x) { return x - (1e8 + 10.0); });
  SolverOptions o;
  o.stop.max_evaluations = 200;
  Vector<1> x(1e8);
  Summary s =
      PseudoTransientEngine<1>({.initial_pseudo_step = 2.3e-16, .min_pseudo_step = 2.3e-16}, o)
          .solve(far, x);
  EXPECT_FALSE(s.converged()) << s.full_report();
  EXPECT_EQ(s.status, Status::kStagnated);
  EXPECT_NE(s.message.find("progress_window"), std::string::npos) << s.message;
  EXPECT_GT(x[0], 1e8);  // it moved
  x[0] = 1e8;
  o.stop.progress_window = 0;
  s = PseudoTransientEngine<1>({.initial_pseudo_step = 2.3e-16, .min_pseudo_step = 2.3e-16}, o)
          .solve(far, x);
  EXPECT_FALSE(s.converged()) << s.full_report();
  EXPECT_EQ(s.status, Status::kMaxEvaluations);
  EXPECT_GT(x[0], 1e8);
  // From δ₀ = 1e-2 (the default) the same problem is solved in a few steps.
  x[0] = 1e8;
  s = PseudoTransientEngine<1>({}, o).solve(far, x);
  EXPECT_TRUE(s.converged()) << s.full_report();
  EXPECT_NEAR(x[0], 1e8 + 10.0, 1e-6);
}

TEST(NewtonTrustRegion, ConvergesWhereThePlainStepDivergesAndIsStillNewton) {
  const auto problem = scalar_root(kAtan);
  Vector<1> x(10.0);
  const Summary s = NewtonEngine<1>({.trust_region = true}, strict()).solve(problem, x);
  ASSERT_TRUE(s.converged()) << s.full_report();
  EXPECT_NEAR(x[0], 0.0, 1e-12);
  EXPECT_EQ(s.engine, "newton");
  EXPECT_GE(s.jacobian_evaluations, s.iterations);  // a Jacobian at every iterate
  EXPECT_NE(test::message_of([] {
              NewtonEngine<1>({.line_search = true, .trust_region = true});
            }).find("choose one"),
            std::string::npos);
  EXPECT_EQ(EngineRegistry<>::global().create("newton:trustregion=1")->name(), "newton");
}

}  // namespace
}  // namespace nlobs
