// Levenberg–Marquardt on a sparse Jacobian (the damped normal equations by CHOLMOD,
// NormalEquationsCholesky) against the dense path (QR, MINPACK's lmpar), on problems nlobs does
// not ship: an inconsistent nonlinear least-squares problem (a smoothed exponential fit, m = 2n −
// 1, its minimum with ‖F‖ > 0), Broyden's tridiagonal system, a variable no residual depends on
// (JᵀJ singular), a Jacobian that is infinite at the start; the factorisation's own answers
// against dense algebra, and bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include "invalid_argument_message.hpp"
#include "large_test_problems.hpp"
#include "nlobs/solvers/builtin_engines.hpp"
#include "nlobs/solvers/engine_registry.hpp"
#include "nlobs/solvers/levenberg_marquardt_engine.hpp"
#include "nlobs/solvers/linear/normal_equations_cholesky.hpp"
#include "nlobs/solvers/root_adapter.hpp"
#include "nlobs/solvers/sparse/sparse_problem.hpp"
#include "short_tests.hpp"
#include "test_support.hpp"

namespace nlobs {
namespace {

using Lm = LevenbergMarquardtEngine<>;

// test::smoothed_fit (large_test_problems.hpp): an inconsistent fit, m = 2n − 1.
struct SmoothedFit {
  Index n;
  explicit SmoothedFit(Index size) : n(size) {}
  Index residuals() const { return 2 * n - 1; }
  auto f() const { return test::smoothed_fit(test::smoothed_fit_data(n)); }
  RootProblem<> dense() const { return RootProblem<>::with_dense_autodiff(f(), n, residuals()); }
  RootProblem<> detected() const { return RootProblem<>::with_autodiff(f(), n, residuals()); }
  RootProblem<> declared() const {
    return sparse_autodiff_problem(f(), Vector<Dynamic>::Zero(n), residuals());
  }
};

SolverOptions least_squares_stop() {
  SolverOptions o;
  o.stop.max_iterations = 200;
  return o;
}

// One least-squares problem solved from x0 on the dense path (QR, `dense`) and on the sparse one
// (CHOLMOD, `sparse`), by engines alike but for the problem; check() asserts both converged and
// the sparse one on CHOLMOD.
struct BothPaths {
  Summary dense, sparse;
  Vector<Dynamic> dense_x, x;

  BothPaths(const RootProblem<>& dense_problem, const RootProblem<>& sparse_problem,
            const Vector<Dynamic>& x0, const LevenbergMarquardtOptions& lm = {},
            const SolverOptions& options = least_squares_stop(), const BoxBounds& box = {})
      : dense_x(x0), x(x0) {
    Lm dense_lm(lm, options), sparse_lm(lm, options);
    if (box.lower.size() != 0 || box.upper.size() != 0) {
      dense_lm.set_bounds(box);
      sparse_lm.set_bounds(box);
    }
    dense = dense_lm.solve_least_squares(dense_problem, dense_x);
    sparse = sparse_lm.solve_least_squares(sparse_problem, x);
  }
  void check() const {
    ASSERT_EQ(dense.status, Status::kConverged) << dense.full_report();
    ASSERT_EQ(sparse.status, Status::kConverged) << sparse.full_report();
    EXPECT_TRUE(dense.linear_solver.empty());
    EXPECT_EQ(sparse.linear_solver, "cholmod");
  }
};

TEST(SparseLeastSquares, AnInconsistentFitMatchesTheDensePath) {
  const SmoothedFit fit(300);
  const Vector<Dynamic> x0 = Vector<Dynamic>::Zero(fit.n);
  Lm dense_lm({}, least_squares_stop());
  Vector<Dynamic> dense_x = x0;
  const Summary dense = dense_lm.solve_least_squares(fit.dense(), dense_x);
  ASSERT_EQ(dense.status, Status::kConverged) << dense.full_report();
  EXPECT_TRUE(dense.linear_solver.empty());

  const RootProblem<> detected = fit.detected();
  for (const auto& [label, problem] :
       {std::pair{"declared", fit.declared()}, std::pair{"detected", detected}}) {
    Lm lm({}, least_squares_stop());
    Vector<Dynamic> x = x0;
    const Summary s = lm.solve_least_squares(problem, x);
    ASSERT_EQ(s.status, Status::kConverged) << label << ": " << s.full_report();
    EXPECT_EQ(s.linear_solver, "cholmod") << label;
    EXPECT_GE(s.linear_setups, s.jacobian_evaluations) << label << ": one factor per lambda tried";
    EXPECT_LE((x - dense_x).lpNorm<Eigen::Infinity>(), 1e-7) << label;
    // The same minimum, its residual far from 0: a least-squares answer, not a root.
    EXPECT_NEAR(s.residual_norm, dense.residual_norm, 1e-9) << label;
    EXPECT_GT(s.residual_norm, 1e-3) << label;
    EXPECT_NEAR(s.iterations, dense.iterations, 1) << label << ": the same lambda iteration";
  }
  EXPECT_EQ(detected.sparse_jacobian_note(),
            "detected: " + std::to_string(4 * fit.n - 3) + " entries");  // 2 a row, 1 in row n − 1
}

TEST(SparseLeastSquares, ScalingAndGeodesicAccelerationMatchTheDensePath) {
  const SmoothedFit fit(200);
  const Vector<Dynamic> x0 = Vector<Dynamic>::Constant(fit.n, 1.5);
  for (const LevenbergMarquardtOptions& options :
       {LevenbergMarquardtOptions{.scale_by_jacobian_columns = true},
        LevenbergMarquardtOptions{.geodesic_acceleration = true}}) {
    const BothPaths run(fit.dense(), fit.declared(), x0, options);
    ASSERT_NO_FATAL_FAILURE(run.check());
    EXPECT_LE((run.x - run.dense_x).lpNorm<Eigen::Infinity>(), 1e-7);
    EXPECT_NEAR(run.sparse.iterations, run.dense.iterations, 1);
    EXPECT_NEAR(run.sparse.function_evaluations, run.dense.function_evaluations, 2);
  }
}

TEST(SparseLeastSquares, MoresLambdaIterationTakesTheDensePathsIterates) {
  // A radius far below the first Gauss–Newton step: every step needs λ > 0 from the secular
  // equation, its Newton corrections from the Cholesky factor (the QR path's from qrsolv).
  const SmoothedFit fit(150);
  const Vector<Dynamic> x0 = Vector<Dynamic>::Constant(fit.n, 3.0);
  SolverOptions options = least_squares_stop();
  options.record_trace = true;
  const BothPaths run(fit.dense(), fit.declared(), x0, {.initial_radius_factor = 1e-3}, options);
  ASSERT_NO_FATAL_FAILURE(run.check());
  const Summary &dense = run.dense, &s = run.sparse;
  ASSERT_EQ(s.iterations, dense.iterations);
  EXPECT_EQ(s.function_evaluations, dense.function_evaluations);
  EXPECT_GT(s.linear_setups, s.jacobian_evaluations) << "several lambdas per Jacobian";
  ASSERT_EQ(s.trace.size(), dense.trace.size());
  for (std::size_t k = 0; k < s.trace.size(); ++k) {
    EXPECT_LE((s.trace[k].x - dense.trace[k].x).lpNorm<Eigen::Infinity>(), 1e-10) << k;
  }
}

TEST(SparseLeastSquares, ABoxThatHoldsVariablesGivesTheDenseMinimumOnTheBox) {
  const SmoothedFit fit(150);
  const Vector<Dynamic> x0 = Vector<Dynamic>::Zero(fit.n);
  // x* = sin(i/7) reaches ±1: a box of ±0.5 holds about a third of the variables.
  const BoxBounds box{Vector<Dynamic>::Constant(fit.n, -0.5),
                      Vector<Dynamic>::Constant(fit.n, 0.5)};
  const BothPaths run(fit.dense(), fit.declared(), x0, {}, least_squares_stop(), box);
  ASSERT_NO_FATAL_FAILURE(run.check());
  const Vector<Dynamic>& x = run.x;
  EXPECT_LE((x - run.dense_x).lpNorm<Eigen::Infinity>(), 1e-7);
  const Index held = (x.array().abs() == 0.5).count();
  EXPECT_GT(held, fit.n / 5) << "the box binds";
  EXPECT_LE(x.cwiseAbs().maxCoeff(), 0.5);
}

TEST(SparseLeastSquares, AVariableNoResidualDependsOnStaysWhereItIs) {
  // x_last appears nowhere: JᵀJ is singular at every point. The dense path's QR takes the basic
  // Gauss–Newton step; the sparse one cannot factor λ = 0 and damps every step, to the same
  // minimum in the other variables.
  const SmoothedFit fit(120);
  auto f = [inner = fit.f()](const auto& x, auto& r) mutable {
    inner(x.head(x.size() - 1).eval(), r);
  };
  const Index n = fit.n + 1, m = fit.residuals();
  Vector<Dynamic> x0 = Vector<Dynamic>::Zero(n);
  x0[n - 1] = 3.0;
  const BothPaths run(RootProblem<>::with_dense_autodiff(f, n, m),
                      sparse_autodiff_problem(f, x0, m), x0);
  ASSERT_NO_FATAL_FAILURE(run.check());
  // λ = 0 does not factor; the smallest λ that does stands in, found once per Jacobian.
  EXPECT_LE(run.sparse.linear_setups, 3 * run.sparse.jacobian_evaluations);
  EXPECT_EQ(run.x[n - 1], 3.0);
  EXPECT_LE((run.x - run.dense_x).lpNorm<Eigen::Infinity>(), 1e-6);
}

TEST(SparseLeastSquares, SolvesASquareSystemThroughItsResidualForm) {
  const Index n = 2000;
  const Vector<Dynamic> x0 = Vector<Dynamic>::Constant(n, -1.0);
  const RootProblem<> problem = sparse_autodiff_problem(test::broyden_tridiagonal(), x0);
  Lm lm({}, test::residual_stop(1e-10, 200));
  Vector<Dynamic> x = x0;
  const Summary s = lm.solve(to_fixed_point(problem), x);
  ASSERT_EQ(s.status, Status::kConverged) << s.full_report();
  EXPECT_EQ(s.linear_solver, "cholmod");
  EXPECT_LE(s.residual_norm, 1e-10);
  Vector<Dynamic> f(n);
  problem.evaluate(x, f);
  EXPECT_LE(f.lpNorm<Eigen::Infinity>(), 1e-10);

  // linear=dense keeps the dense path on the same problem (here at a size it can afford).
  const Index small = 150;
  const Vector<Dynamic> y0 = Vector<Dynamic>::Constant(small, -1.0);
  const auto small_problem = sparse_autodiff_problem(test::broyden_tridiagonal(), y0);
  Lm dense_lm({.linear_solver = "dense"}, test::residual_stop(1e-10, 200));
  Lm sparse_lm({}, test::residual_stop(1e-10, 200));
  Vector<Dynamic> yd = y0, ys = y0;
  const Summary d = dense_lm.solve(to_fixed_point(small_problem), yd);
  const Summary t = sparse_lm.solve(to_fixed_point(small_problem), ys);
  ASSERT_TRUE(d.converged() && t.converged()) << d.full_report() << t.full_report();
  EXPECT_TRUE(d.linear_solver.empty());
  EXPECT_EQ(t.linear_solver, "cholmod");
  EXPECT_LE((yd - ys).lpNorm<Eigen::Infinity>(), 1e-9);
  EXPECT_EQ(d.iterations, t.iterations);

  // Under a scaling (set_scaling, KINSOL's): the scaled problem keeps the sparse path.
  Vector<Dynamic> scale(small);
  for (Index i = 0; i < small; ++i) scale[i] = i % 3 == 0 ? 1e2 : 1e-1;
  Lm dense_scaled({.linear_solver = "dense"}, test::residual_stop(1e-10, 200));
  Lm sparse_scaled({}, test::residual_stop(1e-10, 200));
  for (Lm* engine : {&dense_scaled, &sparse_scaled}) {
    engine->set_scaling({.u_scale = scale, .f_scale = scale.cwiseInverse()});
  }
  yd = y0, ys = y0;
  const Summary ds = dense_scaled.solve(to_fixed_point(small_problem), yd);
  const Summary ss = sparse_scaled.solve(to_fixed_point(small_problem), ys);
  ASSERT_TRUE(ds.converged() && ss.converged()) << ds.full_report() << ss.full_report();
  EXPECT_EQ(ss.linear_solver, "cholmod");
  EXPECT_EQ(ds.iterations, ss.iterations);
  EXPECT_LE((yd - ys).lpNorm<Eigen::Infinity>(), 1e-9);
}

// (5 000 unknowns under the sanitizers, NLOBS_SHORT_TESTS: the same detection and path.)
TEST(SparseLeastSquares, AtTwentyThousandUnknownsTheSparsePathIsTaken) {
  const Index n = test::short_tests() ? 5000 : 20000;
  const SmoothedFit fit(n);
  Lm lm({}, least_squares_stop());
  Vector<Dynamic> x = Vector<Dynamic>::Zero(n);
  const Summary s = lm.solve_least_squares(fit.detected(), x);
  ASSERT_EQ(s.status, Status::kConverged) << s.full_report();
  EXPECT_EQ(s.linear_solver, "cholmod");
  EXPECT_GT(s.residual_norm, 1e-3);
}

TEST(SparseLeastSquares, AnInfiniteJacobianIsNamedNotFactored) {
  // r = (sqrt(x_i) − 1)_i, r_{n+i} = x_i − 1: at x = 0 the derivative of sqrt is infinite.
  const Index n = 150;
  auto f = [](const auto& x, auto& r) {
    using std::sqrt;
    r.resize(2 * x.size());
    for (Index i = 0; i < x.size(); ++i) {
      r[i] = sqrt(x[i]) - 1.0;
      r[x.size() + i] = x[i] - 1.0;
    }
  };
  const Vector<Dynamic> x0 = Vector<Dynamic>::Zero(n);
  Lm lm({}, least_squares_stop());
  Vector<Dynamic> x = x0;
  const Summary s = lm.solve_least_squares(sparse_autodiff_problem(f, x0, 2 * n), x);
  EXPECT_EQ(s.status, Status::kNonFinite) << s.full_report();
  EXPECT_NE(s.message.find("Jacobian"), std::string::npos) << s.message;
  EXPECT_EQ(s.linear_solver, "cholmod") << "stopped on the sparse path";
  EXPECT_EQ(x, x0) << "the last good point is kept";
}

TEST(SparseLeastSquares, AJacobianWhoseColumnNormsOverflowStopsBothPaths) {
  // Entries of 1e160: finite, but ‖J e_j‖ overflows; Moré's scaling would make D infinite and
  // every cosine read 0 (a false gtol convergence at ‖F‖ = 1e160).
  const Index n = 120;
  auto f = [](const auto& x, auto& r) {
    r.resize(2 * x.size());
    for (Index i = 0; i < x.size(); ++i) {
      r[i] = 1e160 * x[i] + 1e160;
      r[x.size() + i] = 1e160 * x[i];
    }
  };
  const Vector<Dynamic> x0 = Vector<Dynamic>::Zero(n);
  for (const std::string linear : {"dense", "cholmod"}) {
    Lm lm({.scale_by_jacobian_columns = true, .linear_solver = linear}, least_squares_stop());
    Vector<Dynamic> x = x0;
    const Summary s = lm.solve_least_squares(sparse_autodiff_problem(f, x0, 2 * n), x);
    EXPECT_EQ(s.status, Status::kNonFinite) << linear << ": " << s.full_report();
    EXPECT_NE(s.message.find("overflow"), std::string::npos) << s.message;
  }
}

TEST(SparseLeastSquares, ATrialPointOutsideFsDomainIsARejectedStepOnBothPaths) {
  // r_i = log(x_i) − 1 (i < n), r_{n+i} = 0.3 (x_{i+1} − x_i): from x = 50 the first
  // Gauss–Newton steps overshoot below 0, where log is NaN; the step is refused and the radius
  // shrinks, on both paths alike.
  const Index n = 150;
  auto nan_steps = std::make_shared<int>(0);
  auto f = [nan_steps](const auto& x, auto& r) {
    using std::log;
    const Index size = x.size();
    r.resize(2 * size - 1);
    for (Index i = 0; i < size; ++i) {
      if constexpr (std::is_same_v<std::decay_t<decltype(x[i])>, double>) {
        if (x[i] <= 0.0) ++*nan_steps;
      }
      r[i] = log(x[i]) - 1.0 - 0.01 * static_cast<double>(i % 5);
      if (i + 1 < size) r[size + i] = 0.3 * (x[i + 1] - x[i]);
    }
  };
  const Vector<Dynamic> x0 = Vector<Dynamic>::Constant(n, 50.0);
  const BothPaths run(RootProblem<>::with_dense_autodiff(f, n, 2 * n - 1),
                      sparse_autodiff_problem(f, x0, 2 * n - 1), x0,
                      {.initial_radius_factor = 1e4});
  ASSERT_NO_FATAL_FAILURE(run.check());
  EXPECT_GT(*nan_steps, 0) << "some trial point left the domain";
  EXPECT_TRUE(run.x.allFinite());
  EXPECT_GT(run.x.minCoeff(), 0.0);
  EXPECT_LE((run.x - run.dense_x).lpNorm<Eigen::Infinity>(), 1e-7);
  EXPECT_EQ(run.sparse.iterations, run.dense.iterations);
}

TEST(SparseLeastSquares, TheEvaluationBudgetHoldsOnTheSparsePath) {
  const SmoothedFit fit(200);
  SolverOptions options = least_squares_stop();
  options.stop.max_evaluations = 3;
  Lm lm({}, options);
  Vector<Dynamic> x = Vector<Dynamic>::Constant(fit.n, 2.0);
  const Summary s = lm.solve_least_squares(fit.declared(), x);
  EXPECT_EQ(s.status, Status::kMaxEvaluations) << s.full_report();
  EXPECT_LE(s.function_evaluations, 3);
  EXPECT_EQ(s.linear_solver, "cholmod");
}

TEST(SparseLeastSquares, OptionsAndSpecsAreCheckedByName) {
  EXPECT_NE(test::invalid_argument_of([] {
              Lm({.linear_solver = "klu"});
            }).find("linear_solver = \"klu\" is invalid: must be auto, dense or cholmod"),
            std::string::npos);
  auto& registry = EngineRegistry<Dynamic>::global();
  for (const std::string spec :
       {"levenberg-marquardt:linear=cholmod", "levenberg-marquardt:linear=dense",
        "levenberg-marquardt:linear=auto"}) {
    EXPECT_NO_THROW(registry.create(spec, {})) << spec;
  }
  EXPECT_NE(test::invalid_argument_of([&] {
              registry.create("levenberg-marquardt:linear=gmres", {});
            }).find("gmres"),
            std::string::npos);
  EXPECT_TRUE(Lm().has_sparse_path());
  EXPECT_FALSE(Lm({.linear_solver = "dense"}).has_sparse_path());
}

// The factorisation itself: (J̃ᵀJ̃ + E + λI) q = b and ‖L⁻¹ P b‖² = bᵀ(…)⁻¹ b against dense
// algebra on a random sparse J, m > n, with a scaling and frozen columns.
TEST(NormalEquationsCholesky, AgreesWithDenseAlgebra) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const Index m = 90, n = 60;
  std::vector<Eigen::Triplet<double>> entries;
  for (Index i = 0; i < m; ++i) {
    entries.emplace_back(i, i % n, 2.0 + uniform(rng));
    for (int k = 0; k < 3; ++k) {
      entries.emplace_back(i, static_cast<Index>(rng() % static_cast<unsigned>(n)), uniform(rng));
    }
  }
  SparseJacobian jac(m, n);
  jac.setFromTriplets(entries.begin(), entries.end());
  jac.makeCompressed();
  Vector<Dynamic> d(n), b(n);
  for (Index j = 0; j < n; ++j) d[j] = 0.5 + std::abs(uniform(rng)), b[j] = uniform(rng);
  std::vector<char> frozen(static_cast<std::size_t>(n), 0);
  frozen[3] = frozen[17] = 1;

  Matrix<Dynamic, Dynamic> jt = Matrix<Dynamic, Dynamic>(jac) * d.cwiseInverse().asDiagonal();
  Matrix<Dynamic, Dynamic> e = Matrix<Dynamic, Dynamic>::Zero(n, n);
  for (const Index j : {3, 17}) jt.col(j).setZero(), e(j, j) = 1.0;

  NormalEquationsCholesky cholesky;
  cholesky.load(jac, d, frozen);
  for (const double lambda : {0.0, 1e-3, 10.0}) {
    ASSERT_TRUE(cholesky.factor(lambda)) << cholesky.message();
    const Matrix<Dynamic, Dynamic> a =
        jt.transpose() * jt + e + lambda * Matrix<Dynamic, Dynamic>::Identity(n, n);
    const Vector<Dynamic> expected = a.ldlt().solve(b);
    Vector<Dynamic> q, y;
    cholesky.solve(b, q);
    EXPECT_LE((q - expected).norm(), 1e-10 * expected.norm()) << lambda;
    cholesky.solve_lower(b, y);
    EXPECT_NEAR(y.squaredNorm(), b.dot(expected), 1e-10 * std::abs(b.dot(expected))) << lambda;
  }
  EXPECT_EQ(cholesky.analyses(), 1);
  cholesky.load(jac, d, frozen);  // the same pattern: the analysis is kept
  EXPECT_EQ(cholesky.analyses(), 1);
  SparseJacobian other = jac;  // another pattern (an entry more in row 0): analysed again
  Index free_column = 0;
  while (jac.coeff(0, free_column) != 0.0) ++free_column;
  other.coeffRef(0, free_column) = 0.5;
  other.makeCompressed();
  ASSERT_EQ(other.nonZeros(), jac.nonZeros() + 1);
  cholesky.load(other, d, frozen);
  EXPECT_EQ(cholesky.analyses(), 2);
  cholesky.load(jac, d, frozen);
  EXPECT_EQ(cholesky.analyses(), 3);

  // A column left out of every row and not frozen: singular at λ = 0, regular above.
  for (Index k = 0; k < jac.nonZeros(); ++k) {
    if (jac.innerIndexPtr()[k] == 5) jac.valuePtr()[k] = 0.0;
  }
  cholesky.load(jac, d, frozen);
  EXPECT_FALSE(cholesky.factor(0.0));
  EXPECT_NE(cholesky.message().find("not positive definite"), std::string::npos);
  EXPECT_TRUE(cholesky.factor(1e-6)) << cholesky.message();

  // Bad input, named; the factor is not touched by a refused load.
  Vector<Dynamic> bad_d = d;
  bad_d[2] = 0.0;
  EXPECT_NE(test::invalid_argument_of([&] { cholesky.load(jac, bad_d, frozen); }).find("d[2]"),
            std::string::npos);
  SparseJacobian with_nan = jac;
  with_nan.valuePtr()[0] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(
      test::invalid_argument_of([&] { cholesky.load(with_nan, d, frozen); }).find("non-finite"),
      std::string::npos);
  EXPECT_NE(test::invalid_argument_of([&] { cholesky.factor(-1.0); }).find("lambda"),
            std::string::npos);
  Vector<Dynamic> q, kept;
  cholesky.solve(b, kept);
  const Matrix<Dynamic, Dynamic> jt5 =
      Matrix<Dynamic, Dynamic>(jac) * d.cwiseInverse().asDiagonal();
  Matrix<Dynamic, Dynamic> a = Matrix<Dynamic, Dynamic>::Identity(n, n) * 1e-6 + e;
  for (Index j = 0; j < n; ++j) {
    for (Index k = 0; k < n; ++k) {
      if (!frozen[static_cast<std::size_t>(j)] && !frozen[static_cast<std::size_t>(k)]) {
        a(j, k) += jt5.col(j).dot(jt5.col(k));
      }
    }
  }
  EXPECT_LE((a * kept - b).norm(), 1e-6 * b.norm()) << "the factor at 1e-6 is still there";
  EXPECT_NE(test::invalid_argument_of([&] {
              cholesky.solve(Vector<Dynamic>::Zero(n + 1), q);
            }).find("solve"),
            std::string::npos);
}

}  // namespace
}  // namespace nlobs
