// Every stop criterion and every status has a test that triggers it.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

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
        Status::kInvalidInput, Status::kSolverFailure, Status::kBlockedByBound}) {
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
