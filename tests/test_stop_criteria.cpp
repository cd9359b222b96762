// Every stop criterion and every status has a test that triggers it.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "nlobs/solvers/engine_registry.hpp"
#include "test_support.hpp"

namespace nlobs {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

FixedPointProblem<1> scalar_map(double (*g)(double)) {
  return FixedPointProblem<1>::from_map(
      [g](const Vector<1>& x, Vector<1>& out) { out[0] = g(x[0]); });
}

// G(x) = x/2 + 1: fixed point 2, Lipschitz constant 1/2.
FixedPointProblem<1> halving() {
  return scalar_map([](double x) { return 0.5 * x + 1.0; });
}

TEST(StopCriteria, StepTolerance) {
  PicardEngine<1> e(test::tolerance(1e-6));
  Vector<1> x(0.0);
  const Summary s = e.solve(halving(), x);
  EXPECT_EQ(s.status, Status::kConverged);
  EXPECT_LE(s.step_norm, 1e-6);
  EXPECT_GT(s.step_norm, 1e-6 / 2.0 - 1e-18);  // the first step below tol, not later
}

TEST(StopCriteria, ResidualToleranceAlone) {
  SolverOptions o;
  o.stop.step_tolerance.reset();
  o.stop.residual_tolerance = 1e-9;
  SteffensenEngine<1> e(o);
  Vector<1> x(1.0);
  const Summary s = e.solve(test::cosine_problem(), x);
  EXPECT_EQ(s.status, Status::kConverged);
  EXPECT_LE(s.residual_norm, 1e-9);
}

TEST(StopCriteria, ErrorBoundWithGivenLipschitz) {
  SolverOptions o;
  o.stop.step_tolerance.reset();
  o.stop.error_tolerance = 1e-6;
  o.stop.lipschitz_constant = 0.5;
  PicardEngine<1> e(o);
  Vector<1> x(0.0);
  const Summary s = e.solve(halving(), x);
  EXPECT_EQ(s.status, Status::kConverged);
  EXPECT_LE(s.step_norm, 0.5 * 1e-6);  // (1 − L) ε
  EXPECT_LE(std::abs(x[0] - 2.0), 1e-6);
  ASSERT_TRUE(s.error_bound.has_value());
  EXPECT_FALSE(s.lipschitz_is_estimate);
  EXPECT_LE(std::abs(x[0] - 2.0), *s.error_bound * (1.0 + 1e-12));  // the bound holds
  ASSERT_TRUE(s.a_priori_iterations.has_value());
  EXPECT_EQ(*s.a_priori_iterations, 20);  // ⌈6 / log10 2⌉
}

TEST(StopCriteria, ErrorBoundWithEstimatedLipschitz) {
  SolverOptions o;
  o.stop.step_tolerance.reset();
  o.stop.error_tolerance = 1e-8;
  PicardEngine<1> e(o);
  Vector<1> x(1.0);
  const Summary s = e.solve(test::cosine_problem(), x);
  EXPECT_EQ(s.status, Status::kConverged);
  EXPECT_TRUE(s.lipschitz_is_estimate);
  ASSERT_TRUE(s.lipschitz_constant.has_value());
  EXPECT_NEAR(*s.lipschitz_constant, std::sin(test::kDottie), 0.02);  // |G'(p)|
  EXPECT_LE(std::abs(x[0] - test::kDottie), 1e-8);
}

TEST(StopCriteria, ErrorToleranceNeedsLipschitzOutsidePicard) {
  SolverOptions o;
  o.stop.error_tolerance = 1e-8;
  EXPECT_THROW(AndersonEngine<1>({}, o), InvalidInput);
  EXPECT_THROW(NewtonEngine<1>({}, o), InvalidInput);
  o.stop.lipschitz_constant = 0.7;
  EXPECT_NO_THROW(AndersonEngine<1>({}, o));
}

TEST(StopCriteria, CombineAllNeedsEveryCriterion) {
  SolverOptions any;
  any.stop.step_tolerance = 1e-3;
  any.stop.residual_tolerance = 1e-12;
  SolverOptions all = any;
  all.stop.combine = Combine::kAll;
  Vector<1> xa(0.0), xb(0.0);
  const Summary sa = PicardEngine<1>(any).solve(halving(), xa);
  const Summary sb = PicardEngine<1>(all).solve(halving(), xb);
  EXPECT_TRUE(sa.converged());
  EXPECT_TRUE(sb.converged());
  EXPECT_LT(sa.iterations, sb.iterations);
  EXPECT_LE(sb.step_norm, 1e-12);
}

TEST(Status, MaxIterations) {
  SolverOptions o = test::tolerance(1e-14);
  o.stop.max_iterations = 3;
  Vector<1> x(1.0);
  const Summary s = PicardEngine<1>(o).solve(test::cosine_problem(), x);
  EXPECT_EQ(s.status, Status::kMaxIterations);
  EXPECT_EQ(s.iterations, 3);
}

TEST(Status, MaxEvaluations) {
  SolverOptions o = test::tolerance(1e-14);
  o.stop.max_evaluations = 5;
  Vector<1> x(1.0);
  const Summary s = SteffensenEngine<1>(o).solve(test::cosine_problem(), x);
  EXPECT_EQ(s.status, Status::kMaxEvaluations);
  EXPECT_EQ(s.function_evaluations, 5 + 1);  // + the residual check at the returned point
  EXPECT_EQ(s.iterations, 2);
}

TEST(Status, StagnatedOnTwoCycle) {
  // G(x) = −x from 1 alternates ±1 forever: the step never shrinks.
  Vector<1> x(1.0);
  const Summary s = PicardEngine<1>().solve(scalar_map([](double v) { return -v; }), x);
  EXPECT_EQ(s.status, Status::kStagnated);
  EXPECT_EQ(s.iterations, 6);  // first step, then patience (5) steps that do not shrink
  EXPECT_TRUE(std::isfinite(x[0]));
}

TEST(Status, PapersStagnationRuleStopsAtFirstNonShrinkingStep) {
  SolverOptions o;
  o.stop.stagnation_patience = 1;  // eq. (72)
  Vector<1> x(1.0);
  const Summary s = PicardEngine<1>(o).solve(scalar_map([](double v) { return -v; }), x);
  EXPECT_EQ(s.status, Status::kStagnated);
  EXPECT_EQ(s.iterations, 2);
}

TEST(Status, RepeatedIteratesWithoutToleranceNeverDividesByZero) {
  // No convergence criterion: run until the floating-point iteration stops moving. x/2 + 1
  // reaches 2 exactly; Aitken's and Steffensen's Δ² then has a zero denominator (Remark 8).
  SolverOptions o;
  o.stop.step_tolerance.reset();
  for (Engine<1>* e : std::initializer_list<Engine<1>*>{
           new PicardEngine<1>(o), new AitkenEngine<1>(o), new SteffensenEngine<1>(o),
           new AndersonEngine<1>({.depth = 2}, o)}) {
    Vector<1> x(0.0);
    const Summary s = e->solve(halving(), x);
    EXPECT_EQ(s.status, Status::kRepeatedIterates) << e->name() << '\n' << s.full_report();
    EXPECT_EQ(x[0], 2.0) << e->name();
    EXPECT_EQ(s.residual_norm, 0.0);
    delete e;
  }
}

TEST(Status, DivergedByGrowingSteps) {
  Vector<1> x(1.0);
  const Summary s = PicardEngine<1>().solve(scalar_map([](double v) { return 2.0 * v + 1.0; }), x);
  EXPECT_EQ(s.status, Status::kDiverged);
  EXPECT_LT(s.iterations, 10);
}

// Hammarling's matrix square root (S. J. Hammarling, in Burkardt's test_nonlin, problems 15 and
// 16): X² = A with A = 1e-4 I + e₁e₂ᵀ, X stored row by row, from X = I; the published root has
// X₁₁ = X₂₂ (= X₃₃) = 0.01, X₁₂ = 50. Newton's steps grow from 0.5 to 15 while ‖F‖ falls at
// every step: the way in to the root, not divergence.
RootProblem<Dynamic> matrix_square_root(Index m) {
  return RootProblem<Dynamic>::with_autodiff(
      [m](const auto& x) {
        using T = typename std::decay_t<decltype(x)>::Scalar;
        using RowMajor = Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
        const RowMajor xm = Eigen::Map<const RowMajor>(x.data(), m, m);
        RowMajor f = xm * xm;
        f.diagonal().array() -= T(1e-4);
        f(0, 1) -= 1.0;
        return Vector<Dynamic, T>(f.template reshaped<Eigen::RowMajor>());
      },
      m * m, m * m);
}

TEST(Status, GrowingStepsWithFallingResidualAreNotDivergence) {
  for (Index m : {2, 3}) {
    SCOPED_TRACE("matrix square root, m = " + std::to_string(m));
    const FixedPointProblem<Dynamic> problem = to_fixed_point(matrix_square_root(m));
    SolverOptions o;
    o.stop.step_tolerance = 1e-10;
    o.record_trace = true;
    NewtonEngine<Dynamic> newton({}, o);
    Vector<Dynamic> x = Eigen::MatrixXd::Identity(m, m).reshaped<Eigen::RowMajor>();
    const Summary s = newton.solve(problem, x);
    ASSERT_EQ(s.status, Status::kConverged) << s.full_report();
    EXPECT_LE(s.residual_norm, 1e-8);
    Eigen::MatrixXd published = 0.01 * Eigen::MatrixXd::Identity(m, m);
    published(0, 1) = 50.0;
    EXPECT_LE((x - published.reshaped<Eigen::RowMajor>()).lpNorm<Eigen::Infinity>(), 1e-10)
        << x.transpose();
    // The run did exercise the rule: five steps in a row that did not shrink, growing more than
    // divergence_growth (10×) over them, with ‖F‖ falling at each.
    bool exercised = false;
    for (size_t k = 1; k + 5 <= s.trace.size() && !exercised; ++k) {
      bool non_shrinking = true, falling = true;
      for (size_t j = k; j < k + 5; ++j) {
        non_shrinking = non_shrinking && s.trace[j].step_norm >= s.trace[j - 1].step_norm;
        falling = falling && s.trace[j].residual_norm < s.trace[j - 1].residual_norm;
      }
      exercised =
          non_shrinking && falling && s.trace[k + 4].step_norm > 10.0 * s.trace[k - 1].step_norm;
    }
    EXPECT_TRUE(exercised) << s.full_report();
    // auto's first stage is that Newton: it no longer hands the problem on with a false verdict
    // (before, dogleg and levenberg-marquardt then spent the budget); 13 evaluations at this step
    // tolerance, as many as KINSOL and GSL's gnewton take.
    Vector<Dynamic> xa = Eigen::MatrixXd::Identity(m, m).reshaped<Eigen::RowMajor>();
    const Summary sa = EngineRegistry<Dynamic>::global().create("auto", o)->solve(problem, xa);
    EXPECT_EQ(sa.status, Status::kConverged) << sa.full_report();
    EXPECT_LE(sa.function_evaluations, 13);
    // The paper's step-only rule (patience 1) still stops it at its first growing step.
    SolverOptions paper = o;
    paper.stop.stagnation_patience = 1;
    Vector<Dynamic> xp = Eigen::MatrixXd::Identity(m, m).reshaped<Eigen::RowMajor>();
    EXPECT_NE(NewtonEngine<Dynamic>({}, paper).solve(problem, xp).status, Status::kConverged);
  }
}

TEST(Status, AnUnknownResidualLeavesTheStepRuleAndNoFloor) {
  // An engine that reports no residual (NaN) or a non-finite one: the step rule alone decides,
  // and no rounding floor is named however small the steps.
  SolverOptions o;
  o.stop.step_tolerance.reset();
  o.stop.residual_tolerance = 1e-300;
  for (const double residual : {kNaN, std::numeric_limits<double>::infinity()}) {
    StopMonitor growing(o.stop, 1.0, false);
    std::optional<Status> end;
    double step = 1.0;
    for (int k = 0; k < 10 && !end; ++k, step *= 2.0) end = growing.update(step, residual, 1.0);
    EXPECT_EQ(end, Status::kDiverged);
    EXPECT_EQ(growing.iterations(), 6);  // first step, then patience (5) growing steps
    StopMonitor tiny(o.stop, 1.0, false);
    end.reset();
    for (int k = 0; k < 10 && !end; ++k) end = tiny.update(1e-300 * (10 - k), residual, 1.0);
    EXPECT_EQ(end, std::nullopt);  // shrinking steps, no residual: nothing to judge by
  }
}

TEST(Status, GrowingStepsWithGrowingResidualAreDivergence) {
  // F(x) = sign(x)|x|^(1/3): Newton's map is x ← −2x, the step doubles and |F| grows by 2^(1/3)
  // every iteration; x stays far below divergence_limit, so the growth rule must name it.
  const auto cube_root = to_fixed_point(RootProblem<1>::with_jacobian(
      [](const Vector<1>& x, Vector<1>& f) { f[0] = std::cbrt(x[0]); },
      [](const Vector<1>& x, Matrix<1, 1>& j) {
        j(0, 0) = 1.0 / (3.0 * std::cbrt(x[0]) * std::cbrt(x[0]));
      }));
  Vector<1> x(0.1);
  const Summary s = NewtonEngine<1>().solve(cube_root, x);
  EXPECT_EQ(s.status, Status::kDiverged) << s.full_report();
  EXPECT_LT(s.iterations, 10);
  EXPECT_LT(std::abs(x[0]), 1e3);
}

// Three quadrics in x ≈ 3.5e4 whose terms (≈ 1e9) cancel: ‖F‖ cannot go below the rounding of
// those terms (≈ 1e-7), far above residual_tolerance, and Newton's steps there are J⁻¹ times that
// noise, above an absolute step tolerance of 1e-12 and jittering, so that the stagnation rule
// (five steps in a row that do not shrink) never fires either. Before the rounding-floor test this
// instance ran to max_iterations (2000 here; 10 000 by default) — and so did 24 of 100 random
// instances of the same form, the others stagnating after 12 iterations; now all 100 end
// rounding_floor after at most 10 (docs/solvers.md).
FixedPointProblem<3> cancelling_quadrics() {
  auto f = [](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    Eigen::Matrix<T, 3, 1> out;
    out << x[0] * x[0] - x[1] * x[2] + 0.99718480823026556 * x[1] * x[1],
        x[1] * x[1] - x[2] * x[0] + 0.55953441682089933 * x[2] * x[2],
        x[2] * x[2] - x[0] * x[1] + 0.47687466866338357 * x[0] * x[0];
    return out;
  };
  // The constants: F at a point of no special form, shifted by a few times its rounding, so that
  // no representable x is a root.
  const Vector<3> near_root(35099.808103093055, 34947.217795259632, 34979.316145232522);
  const Vector<3> c = f(near_root) + Vector<3>(-2.241785194788779e-07, 3.3949208089409421e-07,
                                               8.7107814540936026e-07);
  return to_fixed_point(RootProblem<3>::with_autodiff([f, c](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    return Eigen::Matrix<T, 3, 1>(f(x) - c.template cast<T>());
  }));
}

TEST(Status, RoundingFloorEndsARunThatCannotGetCloser) {
  SolverOptions o;
  o.stop.step_tolerance = 1e-12;
  o.stop.residual_tolerance = 1e-12;
  o.record_trace = true;
  Vector<3> x(30000.0, 40000.0, 33000.0);
  const Summary s = NewtonEngine<3>({}, o).solve(cancelling_quadrics(), x);
  ASSERT_EQ(s.status, Status::kRoundingFloor) << s.full_report();
  EXPECT_EQ(to_string(s.status), "rounding_floor");
  EXPECT_LE(s.iterations, 20);
  EXPECT_GT(s.residual_norm, 1e-12);  // the tolerance was out of reach: the test is needed
  EXPECT_TRUE(s.usable()) << s.unusable_reason();  // ‖F‖ meets acceptance_tolerance (1e-6)
  EXPECT_LE(s.step_norm,
            1e4 * std::numeric_limits<double>::epsilon() * (x.lpNorm<Eigen::Infinity>() + 1.0));
  // With acceptance_tolerance below the floor the same answer is not usable, and says why.
  o.stop.acceptance_tolerance = 1e-12;
  Vector<3> y(30000.0, 40000.0, 33000.0);
  const Summary strict = NewtonEngine<3>({}, o).solve(cancelling_quadrics(), y);
  EXPECT_EQ(strict.status, Status::kRoundingFloor);
  EXPECT_FALSE(strict.usable());
  EXPECT_NE(strict.unusable_reason().find("rounding_floor with |F|"), std::string::npos)
      << strict.unusable_reason();
}

TEST(Status, RoundingFloorIsNotSlowLinearConvergence) {
  // Picard on G(x) = 0.99 x + 350 converges to 3.5e4 with steps that shrink 1 % per iteration:
  // when they reach rounding level in x (7.8e-8 at 3.5e4) the residual still falls, so no floor
  // is named until it stops falling, within a few ulps of the fixed point.
  SolverOptions o;
  o.stop.step_tolerance.reset();
  o.stop.residual_tolerance = 1e-300;  // unreachable: run to the end of the sequence
  Vector<1> x(0.0);
  const Summary s =
      PicardEngine<1>(o).solve(scalar_map([](double v) { return 0.99 * v + 350.0; }), x);
  EXPECT_TRUE(s.status == Status::kRoundingFloor || s.status == Status::kRepeatedIterates)
      << s.full_report();
  // It stops once ‖F‖, counted in ulps of x (7.3e-12 there), no longer falls for three iterations
  // (measured: 2.1e-8 from the fixed point); the steps reached rounding level much earlier, at
  // 7.8e-6 from it.
  EXPECT_NEAR(x[0], 35000.0, 1e-7);
}

TEST(Status, DivergedByLimit) {
  SolverOptions o;
  o.stop.stagnation_patience = 0;
  o.stop.divergence_limit = 1e3;
  Vector<1> x(1.0);
  const Summary s = PicardEngine<1>(o).solve(scalar_map([](double v) { return 1.1 * v + 1.0; }), x);
  EXPECT_EQ(s.status, Status::kDiverged);
  EXPECT_GT(std::abs(x[0]), 1e3);
}

TEST(Status, NonFiniteValueReturnsLastFiniteIterate) {
  // G(x) = x − 1 while x > 0.5, NaN below: Picard runs 2.2 → 1.2 → 0.2 → NaN.
  const auto shift = scalar_map([](double v) { return v > 0.5 ? v - 1.0 : kNaN; });
  Vector<1> x(2.2);
  const Summary s = PicardEngine<1>(test::tolerance(1e-12)).solve(shift, x);
  EXPECT_EQ(s.status, Status::kNonFinite);
  EXPECT_NEAR(x[0], 0.2, 1e-12);

  // G(x) = x/2 while x > 0.5: Newton's first step lands on 0, where G is NaN.
  const auto halve = scalar_map([](double v) { return v > 0.5 ? 0.5 * v : kNaN; });
  Vector<1> xn(2.2);
  const Summary sn = NewtonEngine<1>({}, test::tolerance(1e-12)).solve(halve, xn);
  EXPECT_EQ(sn.status, Status::kNonFinite);
  EXPECT_EQ(xn[0], 2.2);
}

TEST(Status, SingularJacobian) {
  // F(x) = [x1 + x2 − 1, 2x1 + 2x2 − 3]: ∂F has rank 1 everywhere.
  const auto problem = to_fixed_point(RootProblem<2>::with_autodiff([](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    Eigen::Matrix<T, 2, 1> f;
    f << x[0] + x[1] - 1.0, 2.0 * x[0] + 2.0 * x[1] - 3.0;
    return f;
  }));
  Vector<2> x(0.3, 0.4);
  const Summary s = NewtonEngine<2>().solve(problem, x);
  EXPECT_EQ(s.status, Status::kSingularJacobian);
  EXPECT_FALSE(s.message.empty());
  EXPECT_EQ(x, Vector<2>(0.3, 0.4));  // last good state kept
}

TEST(Status, InvalidInputReportedBySolveOrReport) {
  PicardEngine<Dynamic> e;
  const auto problem = FixedPointProblem<Dynamic>::from_map(
      [](const Vector<Dynamic>& x, Vector<Dynamic>& g) { g = 0.5 * x; }, 3);
  Vector<Dynamic> x = Vector<Dynamic>::Zero(2);
  const Summary s = solve_or_report(e, problem, x);
  EXPECT_EQ(s.status, Status::kInvalidInput);
  EXPECT_NE(s.message.find("size 2"), std::string::npos) << s.message;
}

TEST(Status, EveryStatusHasAName) {
  for (Status st :
       {Status::kConverged, Status::kMaxIterations, Status::kMaxEvaluations, Status::kStagnated,
        Status::kRepeatedIterates, Status::kDiverged, Status::kNonFinite, Status::kSingularJacobian,
        Status::kInvalidInput, Status::kSolverFailure, Status::kBlockedByBound,
        Status::kRoundingFloor, Status::kLocalMinimum, Status::kStoppedByCallback}) {
    EXPECT_NE(to_string(st), "unknown");
  }
}

TEST(Summary, ReportsMentionTheEssentials) {
  Vector<1> x(1.0);
  SolverOptions o = test::tolerance(1e-10);
  o.record_trace = true;
  const Summary s = SteffensenEngine<1>(o).solve(test::cosine_problem(), x);
  const std::string brief = s.brief_report(), full = s.full_report();
  EXPECT_NE(brief.find("steffensen: converged after"), std::string::npos) << brief;
  EXPECT_NE(brief.find("|F|"), std::string::npos) << brief;
  EXPECT_NE(full.find("function evaluations"), std::string::npos);
  ASSERT_EQ(static_cast<int>(s.trace.size()), s.iterations);
  EXPECT_EQ(s.trace.back().step_norm, s.step_norm);
}

}  // namespace
}  // namespace nlobs
