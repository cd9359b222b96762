// Each engine on problems with known fixed points, fixed and dynamic sizes.
#include <gtest/gtest.h>

#include "test_support.hpp"

namespace nlobs {
namespace {

using test::kDottie;

template <typename Engine>
void expect_dottie(Engine engine) {
  Vector<1> x(1.0);
  const Summary s = engine.solve(test::cosine_problem(), x);
  EXPECT_EQ(s.status, Status::kConverged) << s.full_report();
  EXPECT_NEAR(x[0], kDottie, 1e-9) << engine.name();
  EXPECT_LE(s.step_norm, 1e-10);
  EXPECT_LT(s.residual_norm, 1e-9);
  EXPECT_EQ(s.engine, engine.name());
}

TEST(Engines, EachSolvesCosineFixedPoint) {
  const SolverOptions o = test::tolerance(1e-12);
  expect_dottie(PicardEngine<1>(o));
  expect_dottie(AitkenEngine<1>(o));
  expect_dottie(SteffensenEngine<1>(o));
  expect_dottie(AndersonEngine<1>({.depth = 2}, o));
  expect_dottie(NewtonEngine<1>({}, o));
  expect_dottie(NewtonEngine<1>({.line_search = true}, o));
}

// Summary::engine holds its own copy of the name: it stays right after the engine is gone, for an
// engine that names itself from a string it owns (a plugin's may), and is cut at 64 bytes on a
// UTF-8 boundary.
TEST(Engines, TheSummaryKeepsTheEngineNameAfterTheEngineIsGone) {
  class Named : public PicardEngine<1> {
   public:
    Named(std::string name, SolverOptions o) : PicardEngine<1>(o), name_(std::move(name)) {}
    std::string_view name() const override { return name_; }

   private:
    std::string name_;
  };
  // On the heap, with a name past the small-string buffer: a view into it would dangle.
  const std::string name = "my-own-over-relaxed-picard-engine";
  auto engine = std::make_unique<Named>(name, test::tolerance(1e-12));
  Vector<1> x(1.0);
  const Summary s = engine->solve(test::cosine_problem(), x);
  engine.reset();  // the engine and its string are gone
  EXPECT_EQ(s.engine, name);
  EXPECT_EQ(std::string(s.engine), name);
  EXPECT_NE(s.brief_report().find(name), std::string::npos) << s.brief_report();

  const std::string long_name = std::string(63, 'a') + "é-tail";  // 'é' straddles byte 64
  const EngineName cut(long_name);
  EXPECT_EQ(cut.size(), 63u);
  EXPECT_EQ(cut.view(), std::string(63, 'a'));
  EXPECT_EQ(EngineName(std::string(64, 'b')).size(), 64u);
  EXPECT_EQ(EngineName(std::string(100, 'c')).size(), EngineName::kCapacity);
  EXPECT_TRUE(EngineName().empty());
}

TEST(Engines, AccelerationOrdersIterationCountsOnCosine) {
  const SolverOptions o = test::tolerance(1e-12);
  auto iterations = [&](Engine<1>&& e) {
    Vector<1> x(1.0);
    return e.solve(test::cosine_problem(), x).iterations;
  };
  const int picard = iterations(PicardEngine<1>(o));
  const int aitken = iterations(AitkenEngine<1>(o));
  const int steffensen = iterations(SteffensenEngine<1>(o));
  const int newton = iterations(NewtonEngine<1>({}, o));
  EXPECT_GT(picard, aitken);
  EXPECT_GT(aitken, steffensen);
  EXPECT_LE(newton, 6);
}

TEST(Engines, DynamicSizeMatchesFixedSize) {
  const auto g = [](const auto& x) {
    using std::cos;
    using T = typename std::decay_t<decltype(x)>::Scalar;
    Eigen::Matrix<T, Eigen::Dynamic, 1> out(x.size());
    for (Index i = 0; i < x.size(); ++i) out[i] = cos(x[i]) / T(1.0 + double(i));
    return out;
  };
  const auto dyn = FixedPointProblem<Dynamic>::with_autodiff(g, 4);
  const auto fix = FixedPointProblem<4>::with_autodiff(g);
  const SolverOptions o = test::tolerance(1e-12);
  Vector<Dynamic> xd = Vector<Dynamic>::Zero(4);
  Vector<4> xf = Vector<4>::Zero();
  SteffensenEngine<Dynamic> sd(o);
  SteffensenEngine<4> sf(o);
  EXPECT_TRUE(sd.solve(dyn, xd).converged());
  EXPECT_TRUE(sf.solve(fix, xf).converged());
  EXPECT_LT((xd - xf).lpNorm<Eigen::Infinity>(), 1e-12);
  for (Engine<Dynamic>* e : std::initializer_list<Engine<Dynamic>*>{
           new PicardEngine<Dynamic>(o), new AitkenEngine<Dynamic>(o),
           new AndersonEngine<Dynamic>({.depth = 3}, o), new NewtonEngine<Dynamic>({}, o)}) {
    Vector<Dynamic> x = Vector<Dynamic>::Zero(4);
    const Summary s = e->solve(dyn, x);
    EXPECT_TRUE(s.converged()) << s.full_report();
    EXPECT_LT((x - xf).lpNorm<Eigen::Infinity>(), 1e-10) << e->name();
    delete e;
  }
}

TEST(Engines, AitkenIsExactOnDiagonalLinearContraction) {
  // Exact in exact arithmetic; in floating point the Δ² value carries a rounding error of
  // about ε|p|/(1 − r)², hence the 1e-9 tolerance.
  const Eigen::Vector3d rates(0.9, -0.5, 0.95), b(1.0, 2.0, -3.0);
  const Eigen::Vector3d p = b.cwiseQuotient(Eigen::Vector3d::Ones() - rates);
  const auto problem = test::diagonal_linear_problem(rates, b);
  const SolverOptions o = test::tolerance(1e-9);
  {
    AitkenEngine<3> aitken(o);
    Vector<3> x(0.0, 0.0, 0.0);
    const Summary s = aitken.solve(problem, x);
    EXPECT_TRUE(s.converged());
    EXPECT_LE(s.iterations, 2);  // the first Δ² value is already p
    EXPECT_LT((x - p).lpNorm<Eigen::Infinity>(), 1e-10);
  }
  {
    SteffensenEngine<3> steffensen(o);
    Vector<3> x(0.0, 0.0, 0.0);
    const Summary s = steffensen.solve(problem, x);
    EXPECT_TRUE(s.converged());
    EXPECT_LE(s.iterations, 2);
    EXPECT_LT((x - p).lpNorm<Eigen::Infinity>(), 1e-10);
  }
  {
    PicardEngine<3> picard(o);  // the slow component (rate 0.95) needs hundreds of steps
    Vector<3> x(0.0, 0.0, 0.0);
    const Summary s = picard.solve(problem, x);
    EXPECT_TRUE(s.converged());
    EXPECT_GT(s.iterations, 400);
    ASSERT_TRUE(s.contraction_estimate.has_value());
    EXPECT_NEAR(*s.contraction_estimate, 0.95, 1e-3);  // the observed rate is the slowest one
  }
}

TEST(Engines, AndersonSolvesLinearSystemInFewIterations) {
  // Non-diagonal contraction: Anderson with depth ≥ n behaves like GMRES on a linear problem.
  Matrix<3, 3> a;
  a << 0.5, 0.3, 0.1, -0.2, 0.6, 0.2, 0.1, -0.1, 0.7;
  const Vector<3> b(1.0, -1.0, 0.5);
  const Vector<3> p = (Matrix<3, 3>::Identity() - a).lu().solve(b);
  const auto problem =
      FixedPointProblem<3>::from_map([a, b](const Vector<3>& x, Vector<3>& g) { g = a * x + b; });
  AndersonEngine<3> anderson({.depth = 3}, test::tolerance(1e-12));
  Vector<3> x = Vector<3>::Zero();
  const Summary s = anderson.solve(problem, x);
  EXPECT_TRUE(s.converged()) << s.full_report();
  EXPECT_LE(s.iterations, 8);
  EXPECT_LT((x - p).lpNorm<Eigen::Infinity>(), 1e-11);

  PicardEngine<3> picard(test::tolerance(1e-12));
  Vector<3> xp = Vector<3>::Zero();
  EXPECT_GT(picard.solve(problem, xp).iterations, 3 * s.iterations);
}

TEST(Engines, AndersonDepthZeroIsDampedPicard) {
  const auto problem = test::cosine_problem();
  SolverOptions o = test::tolerance(1e-12);
  o.record_trace = true;
  AndersonEngine<1> a0({.depth = 0, .damping = 1.0}, o);
  PicardEngine<1> picard(o);
  Vector<1> xa(1.0), xp(1.0);
  const Summary sa = a0.solve(problem, xa), sp = picard.solve(problem, xp);
  ASSERT_EQ(sa.iterations, sp.iterations);
  for (size_t i = 0; i < sa.trace.size(); ++i) EXPECT_EQ(sa.trace[i].x[0], sp.trace[i].x[0]);

  AndersonEngine<1> damped({.depth = 0, .damping = 0.5}, o);
  Vector<1> xd(1.0);
  EXPECT_TRUE(damped.solve(problem, xd).converged());
  EXPECT_NEAR(xd[0], test::kDottie, 1e-10);
}

TEST(Engines, AndersonSurvivesDependentHistory) {
  // G constant in x: every Δf is zero, so no column can enter the history.
  const auto problem = FixedPointProblem<2>::from_map(
      [](const Vector<2>&, Vector<2>& g) { g = Vector<2>(3.0, -1.0); });
  AndersonEngine<2> anderson({.depth = 4}, test::tolerance(1e-12));
  Vector<2> x(0.0, 0.0);
  EXPECT_TRUE(anderson.solve(problem, x).converged());
  EXPECT_EQ(x, Vector<2>(3.0, -1.0));
}

TEST(Engines, NewtonConvergesQuadraticallyOnRootProblem) {
  // F(x) = [x1² + x2² − 4, x1 − x2]: root (√2, √2).
  const auto root = RootProblem<2>::with_autodiff([](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    Eigen::Matrix<T, 2, 1> f;
    f << x[0] * x[0] + x[1] * x[1] - 4.0, x[0] - x[1];
    return f;
  });
  const auto problem = to_fixed_point(root);
  SolverOptions o = test::tolerance(1e-14);
  o.record_trace = true;
  NewtonEngine<2> newton({}, o);
  Vector<2> x(1.0, 2.0);
  const Summary s = newton.solve(problem, x);
  ASSERT_TRUE(s.converged()) << s.full_report();
  EXPECT_NEAR(x[0], std::sqrt(2.0), 1e-14);
  EXPECT_NEAR(x[1], std::sqrt(2.0), 1e-14);
  EXPECT_LE(s.iterations, 7);
  EXPECT_EQ(s.jacobian_evaluations, s.iterations);
  // Quadratic convergence: once small, each step is about the square of the previous one.
  const auto& t = s.trace;
  ASSERT_GE(t.size(), 4U);
  EXPECT_LT(t[t.size() - 2].step_norm, 10.0 * std::pow(t[t.size() - 3].step_norm, 2) + 1e-15);
}

TEST(Engines, NewtonJacobianSourcesAgree) {
  const auto f = [](const auto& x) {
    using std::exp;
    using std::sin;
    using T = typename std::decay_t<decltype(x)>::Scalar;
    Eigen::Matrix<T, 2, 1> r;
    r << exp(x[0]) - 2.0 + 0.1 * sin(x[1]), x[1] * x[1] * x[1] - x[0] - 1.0;
    return r;
  };
  const auto jac = [](const Vector<2>& x, Matrix<2, 2>& j) {
    j << std::exp(x[0]), 0.1 * std::cos(x[1]), -1.0, 3.0 * x[1] * x[1];
  };
  const auto by_ad = to_fixed_point(RootProblem<2>::with_autodiff(f));
  const auto by_user = to_fixed_point(RootProblem<2>::with_jacobian(f, jac));
  const auto by_fd = to_fixed_point(RootProblem<2>::from_map(f));
  EXPECT_EQ(by_ad.jacobian_source(), JacobianSource::kAutoDiff);
  EXPECT_EQ(by_user.jacobian_source(), JacobianSource::kUserSupplied);
  EXPECT_EQ(by_fd.jacobian_source(), JacobianSource::kFiniteDifference);
  Vector<2> xs[4];
  const SolverOptions o = test::tolerance(1e-13);
  Summary s[4];
  s[0] = NewtonEngine<2>({}, o).solve(by_ad, xs[0] = Vector<2>(1.0, 1.0));
  s[1] = NewtonEngine<2>({}, o).solve(by_user, xs[1] = Vector<2>(1.0, 1.0));
  s[2] = NewtonEngine<2>({.finite_difference = FiniteDifference::kCentral}, o)
             .solve(by_fd, xs[2] = Vector<2>(1.0, 1.0));
  s[3] = NewtonEngine<2>({.finite_difference = FiniteDifference::kForward}, o)
             .solve(by_fd, xs[3] = Vector<2>(1.0, 1.0));
  for (int i = 0; i < 4; ++i) {
    EXPECT_TRUE(s[i].converged()) << i << s[i].full_report();
    EXPECT_LT((xs[i] - xs[0]).lpNorm<Eigen::Infinity>(), 1e-11) << i;
  }
  // AD and user Jacobians cost no evaluations; differences cost 2n (central) or n (forward).
  EXPECT_EQ(s[0].function_evaluations, s[0].iterations + 1);
  EXPECT_EQ(s[2].function_evaluations, s[2].iterations * 5 + 1);
  EXPECT_EQ(s[3].function_evaluations, s[3].iterations * 3 + 1);
}

TEST(Engines, NewtonLineSearchRescuesAtan) {
  // F(x) = atan(x) from x0 = 3: plain Newton overshoots further each step.
  const auto problem = to_fixed_point(RootProblem<1>::with_autodiff([](const auto& x) {
    using std::atan;
    using T = typename std::decay_t<decltype(x)>::Scalar;
    Eigen::Matrix<T, 1, 1> r;
    r[0] = atan(x[0]);
    return r;
  }));
  NewtonEngine<1> plain({}, test::tolerance(1e-12));
  Vector<1> x(3.0);
  const Summary sp = plain.solve(problem, x);
  // |x| grows 3 → 9.5 → 124 → 2.4e4 → 9e8, until atan' = 1/(1 + x²) is numerically zero.
  EXPECT_FALSE(sp.converged());
  EXPECT_TRUE(sp.status == Status::kDiverged || sp.status == Status::kSingularJacobian)
      << sp.full_report();
  EXPECT_GT(std::abs(x[0]), 1e3);

  NewtonEngine<1> damped({.line_search = true}, test::tolerance(1e-12));
  x[0] = 3.0;
  const Summary sd = damped.solve(problem, x);
  EXPECT_TRUE(sd.converged()) << sd.full_report();
  EXPECT_NEAR(x[0], 0.0, 1e-12);
}

}  // namespace
}  // namespace nlobs
