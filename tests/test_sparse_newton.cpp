// Newton's sparse path: problems that carry a sparse Jacobian (sparse/sparse_problem.hpp) solved
// with every linear solver of nlobs/solvers/linear/, on problems nlobs does not ship: Broyden's
// tridiagonal function (up to n = 2·10⁵), 2-D Bratu (PETSc's SNES ex5), a singular linear system;
// the same root as the dense path, the counts in the Summary, bounds, coloured differences, and
// the named failures.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "large_test_problems.hpp"
#include "nlobs/solvers/builtin_engines.hpp"
#include "nlobs/solvers/engine_registry.hpp"
#include "nlobs/solvers/newton_engine.hpp"
#include "nlobs/solvers/root_adapter.hpp"
#include "nlobs/solvers/sparse/sparse_problem.hpp"
#include "test_support.hpp"

namespace nlobs {
namespace {

using test::bratu;
using test::broyden_tridiagonal;

Summary solve_with(const std::string& linear, const RootProblem<>& problem, Vector<Dynamic>& x,
                   bool line_search = true) {
  NewtonEngine<> newton(NewtonOptions{.line_search = line_search, .linear_solver = linear},
                        test::residual_stop());
  return newton.solve(to_fixed_point(problem), x);
}

struct Expected {
  std::string spec, name;
  bool krylov;
};
const std::vector<Expected> kLinearSolvers = {{"auto", "band-lu", false},
                                              {"band-lu", "band-lu", false},
                                              {"sparse-lu", "sparse-lu", false},
                                              {"klu", "klu", false},
                                              {"gmres", "gmres", true},
                                              {"gmres:preconditioner=ilu0", "gmres", true},
                                              {"bicgstab:preconditioner=ilu0", "bicgstab", true}};

TEST(SparseNewton, SolvesBroydenTridiagonalWithEveryLinearSolverAtTheDenseRoot) {
  const Index n = 200;
  const Vector<Dynamic> x0 = Vector<Dynamic>::Constant(n, -1.0);
  Vector<Dynamic> dense_root = x0;
  const Summary dense = solve_with(
      "auto", RootProblem<>::with_autodiff(broyden_tridiagonal(), n, n).with_dense_jacobian(),
      dense_root);
  ASSERT_EQ(dense.status, Status::kConverged) << dense.message;
  EXPECT_TRUE(dense.linear_solver.empty()) << "no sparse Jacobian: the dense path";

  const RootProblem<> problem = sparse_autodiff_problem(broyden_tridiagonal(), x0);
  for (const Expected& e : kLinearSolvers) {
    Vector<Dynamic> x = x0;
    const Summary s = solve_with(e.spec, problem, x);
    ASSERT_EQ(s.status, Status::kConverged) << e.spec << ": " << s.message;
    EXPECT_LE(s.residual_norm, 1e-10) << e.spec;
    EXPECT_LE((x - dense_root).lpNorm<Eigen::Infinity>(), 1e-9) << e.spec;
    EXPECT_EQ(s.linear_solver, e.name) << e.spec;
    EXPECT_EQ(s.linear_setups, s.jacobian_evaluations) << e.spec;
    EXPECT_EQ(s.linear_iterations > 0, e.krylov) << e.spec;
    EXPECT_NE(s.full_report().find("linear solver          " + e.name), std::string::npos);
  }
  // Without a line search (what `newton` runs by name): full steps, same root.
  for (const std::string linear : {"klu", "gmres:preconditioner=ilu0"}) {
    Vector<Dynamic> x = x0;
    const Summary s = solve_with(linear, problem, x, /*line_search=*/false);
    ASSERT_EQ(s.status, Status::kConverged) << linear << ": " << s.message;
    EXPECT_LE((x - dense_root).lpNorm<Eigen::Infinity>(), 1e-9) << linear;
  }
  // "dense" keeps the dense path for a problem that has a sparse Jacobian.
  Vector<Dynamic> x = x0;
  const Summary s = solve_with("dense", problem, x);
  ASSERT_EQ(s.status, Status::kConverged);
  EXPECT_TRUE(s.linear_solver.empty());
  EXPECT_LE((x - dense_root).lpNorm<Eigen::Infinity>(), 1e-12);
}

TEST(SparseNewton, SolvesTwoDimensionalBratuByKluAndByNewtonKrylov) {
  const Index s = 30;  // n = 900, bandwidth 30 > kAutoBandWidth: auto is klu
  const Vector<Dynamic> x0 = Vector<Dynamic>::Zero(s * s);
  const RootProblem<> problem = sparse_autodiff_problem(bratu(s), x0);
  Vector<Dynamic> direct = x0, krylov = x0;
  const Summary a = solve_with("auto", problem, direct);
  ASSERT_EQ(a.status, Status::kConverged) << a.message;
  EXPECT_EQ(a.linear_solver, "klu");
  const Summary k = solve_with("gmres:preconditioner=ilu0", problem, krylov);
  ASSERT_EQ(k.status, Status::kConverged) << k.message;
  EXPECT_GT(k.linear_iterations, 0);
  EXPECT_LE((direct - krylov).lpNorm<Eigen::Infinity>(), 1e-8);
  // A Krylov budget of 3 per step: the steps are inexact but reduce |F|, and are taken.
  Vector<Dynamic> short_budget = x0;
  const Summary b = solve_with("gmres:preconditioner=ilu0,max_iterations=3", problem, short_budget);
  ASSERT_EQ(b.status, Status::kConverged) << b.message;
  EXPECT_LE(b.linear_iterations, 3 * b.linear_setups);
  EXPECT_TRUE(b.usable()) << b.unusable_reason();
  // Stopped by the step test (1e-8) after inexact steps: as close as that test asks.
  EXPECT_LE((short_budget - direct).lpNorm<Eigen::Infinity>(), 1e-6);
  // The lower-branch solution is positive and symmetric under swapping the grid's axes.
  EXPECT_GT(direct.minCoeff(), 0.0);
  for (Index r = 0; r < s; ++r) {
    for (Index c = 0; c < r; ++c) EXPECT_NEAR(direct[r * s + c], direct[c * s + r], 1e-9);
  }
}

TEST(SparseNewton, ReachesTwoHundredThousandUnknownsWithoutADenseMatrix) {
  // A dense J would be 320 GB: to_fixed_point must not size one, Newton must not touch one.
  const Index n = 200000;
  const Vector<Dynamic> x0 = Vector<Dynamic>::Constant(n, -1.0);
  const RootProblem<> problem = sparse_autodiff_problem(broyden_tridiagonal(), x0);
  Vector<Dynamic> x = x0;
  const Summary s = solve_with("auto", problem, x);
  ASSERT_EQ(s.status, Status::kConverged) << s.message;
  EXPECT_EQ(s.linear_solver, "band-lu");
  const Vector<Dynamic> f = broyden_tridiagonal()(x);
  EXPECT_LE(f.lpNorm<Eigen::Infinity>(), 1e-10);
}

TEST(SparseNewton, KeepsABindingBoxAsTheDensePathDoes) {
  const Index n = 100;
  const Vector<Dynamic> x0 = Vector<Dynamic>::Constant(n, -1.0);
  const RootProblem<> problem = sparse_autodiff_problem(broyden_tridiagonal(), x0);
  Vector<Dynamic> root = x0;
  ASSERT_EQ(solve_with("klu", problem, root).status, Status::kConverged);
  const double upper = 0.5 * (root.minCoeff() + root.maxCoeff());  // cuts through the root
  for (const bool line_search : {true, false}) {
    std::vector<Summary> summaries;
    std::vector<Vector<Dynamic>> answers;
    for (const std::string linear : {"dense", "klu", "gmres:preconditioner=ilu0"}) {
      NewtonEngine<> newton(NewtonOptions{.line_search = line_search, .linear_solver = linear},
                            test::residual_stop());
      newton.set_bounds({Vector<Dynamic>::Constant(n, -2.0), Vector<Dynamic>::Constant(n, upper)});
      Vector<Dynamic> x = x0;
      summaries.push_back(newton.solve(to_fixed_point(problem), x));
      answers.push_back(x);
      EXPECT_LE(x.maxCoeff(), upper) << linear;
    }
    for (std::size_t k = 1; k < summaries.size(); ++k) {
      EXPECT_EQ(summaries[k].status, summaries[0].status)
          << k << ": " << summaries[k].message << " / " << summaries[0].message;
      EXPECT_LE((answers[k] - answers[0]).lpNorm<Eigen::Infinity>(), 1e-6) << k;
    }
    EXPECT_DOUBLE_EQ(answers[0].maxCoeff(), upper) << "the box binds";
  }
}

TEST(SparseNewton, RefusesWhatWouldTakeTheDensePathAtLargeSize) {
  const Vector<Dynamic> x0 = Vector<Dynamic>::Constant(50, -1.0);
  const FixedPointProblem<> problem =
      to_fixed_point(sparse_autodiff_problem(broyden_tridiagonal(), x0));
  Vector<Dynamic> x = x0;
  NewtonEngine<> trust(NewtonOptions{.trust_region = true});
  EXPECT_THROW(trust.solve(problem, x), InvalidInput);
  NewtonEngine<> dense(NewtonOptions{.trust_region = true, .linear_solver = "dense"},
                       test::residual_stop());
  EXPECT_EQ(dense.solve(problem, x).status, Status::kConverged);
}

// A scaling keeps the sparse path: the scaled problem's Jacobian is D_f J D_u⁻¹ on J's pattern,
// and the iterates are the dense path's (the same scaled Newton steps), whether the pattern is
// declared or detected; unequal scales, a box, and the scaled norms in the Summary.
TEST(SparseNewton, AScalingKeepsTheSparsePathAndTheDensePathsIterates) {
  const Index n = 300;
  const Vector<Dynamic> x0 = Vector<Dynamic>::Constant(n, -1.0);
  Scaling scaling;
  scaling.u_scale = Vector<Dynamic>::LinSpaced(n, 0.5, 4.0);
  scaling.f_scale = Vector<Dynamic>::LinSpaced(n, 3.0, 0.25);
  const RootProblem<> declared = sparse_autodiff_problem(broyden_tridiagonal(), x0);
  const RootProblem<> detected = RootProblem<>::with_autodiff(broyden_tridiagonal(), n, n);
  for (const RootProblem<>* problem : {&declared, &detected}) {
    std::vector<Summary> runs;
    std::vector<Vector<Dynamic>> answers;
    for (const bool sparse : {false, true}) {
      NewtonEngine<> newton(NewtonOptions{.line_search = true}, test::residual_stop(1e-10, 100));
      newton.set_scaling(scaling);
      newton.set_bounds({Vector<Dynamic>::Constant(n, -5.0), Vector<Dynamic>::Constant(n, 5.0)});
      Vector<Dynamic> x = x0;
      runs.push_back(
          newton.solve(to_fixed_point(sparse ? *problem : problem->with_dense_jacobian()), x));
      answers.push_back(x);
      ASSERT_EQ(runs.back().status, Status::kConverged) << sparse << ": " << runs.back().message;
      EXPECT_EQ(runs.back().linear_solver.empty(), !sparse) << runs.back().linear_solver;
    }
    EXPECT_EQ(runs[1].iterations, runs[0].iterations);
    EXPECT_LE((answers[1] - answers[0]).lpNorm<Eigen::Infinity>(), 1e-10);
    Vector<Dynamic> f(n);
    problem->evaluate(answers[1], f);
    EXPECT_NEAR(runs[1].residual_norm, f.cwiseProduct(scaling.f_scale).norm(), 1e-12);
  }
}

// Coloured differences under a scaling: unknowns of order 1e-12 (x_i = c·y_i), brought to order
// 1 by u_scale = 1/c. The differences must step in the scaled variables, as the dense path's
// differences of the scaled problem do; steps √ε·max(1, |x_j|) in x would be 1e4 times the
// unknowns (stagnated before the scaled source differenced F̃ itself).
TEST(SparseNewton, ColouredDifferencesUnderAScalingStepInTheScaledVariables) {
  const Index n = 60;
  const double c = 1e-12;
  // F_i = log(y_i) − 1 + 0.1 (y_{i−1} + y_{i+1} − 2e): the root y = e.
  auto on_doubles = [c](const Vector<Dynamic>& x, Vector<Dynamic>& f) {
    const Index m = x.size();
    f.resize(m);
    const double e = std::exp(1.0);
    for (Index i = 0; i < m; ++i) {
      const double left = i > 0 ? x[i - 1] / c : e, right = i + 1 < m ? x[i + 1] / c : e;
      f[i] = std::log(x[i] / c) - 1.0 + 0.1 * (left + right - 2.0 * e);
    }
  };
  const RootProblem<> problem =
      sparse_difference_problem(on_doubles, SparsityPattern::band(n, 1, 1));
  std::vector<Summary> runs;
  for (const bool sparse : {false, true}) {
    NewtonEngine<> newton(NewtonOptions{.line_search = true}, test::residual_stop(1e-10, 100));
    newton.set_scaling({.u_scale = Vector<Dynamic>::Constant(n, 1.0 / c)});
    newton.set_bounds({.lower = Vector<Dynamic>::Zero(n),
                       .upper = {},
                       .strict_lower = StrictBounds::Constant(n, true)});
    Vector<Dynamic> x = Vector<Dynamic>::Constant(n, c);
    runs.push_back(
        newton.solve(to_fixed_point(sparse ? problem : problem.with_dense_jacobian()), x));
    ASSERT_EQ(runs.back().status, Status::kConverged) << sparse << ": " << runs.back().message;
    EXPECT_EQ(runs.back().linear_solver.empty(), !sparse);
    EXPECT_LE(((x / c).array().log() - 1.0).abs().maxCoeff(), 1e-8);
  }
  EXPECT_EQ(runs[1].iterations, runs[0].iterations);
}

TEST(SparseNewton, UsesColouredDifferences) {
  const Index n = 100;
  const Vector<Dynamic> x0 = Vector<Dynamic>::Constant(n, -1.0);
  // F on doubles only, with a declared tridiagonal pattern: coloured forward differences.
  auto on_doubles = [](const Vector<Dynamic>& x, Vector<Dynamic>& f) {
    f = broyden_tridiagonal()(x);
  };
  const RootProblem<> problem =
      sparse_difference_problem(on_doubles, SparsityPattern::band(n, 1, 1));
  NewtonEngine<> newton(NewtonOptions{.line_search = true, .linear_solver = "klu"},
                        test::residual_stop());
  Vector<Dynamic> x = x0;
  const Summary s = newton.solve(to_fixed_point(problem), x);
  ASSERT_EQ(s.status, Status::kConverged) << s.message;
  const Vector<Dynamic> f = broyden_tridiagonal()(x);
  EXPECT_LE(f.lpNorm<Eigen::Infinity>(), 1e-10);
  // Three colours per Jacobian, one evaluation each, beside the residual evaluations.
  EXPECT_GE(s.function_evaluations, 3 * s.jacobian_evaluations + s.iterations);
}

TEST(SparseNewton, NamesASingularSparseJacobian) {
  // F = (x₀ − x₁, x₁ − x₀ + 1): J = [[1, −1], [−1, 1]] is singular everywhere, no root.
  auto singular = [](const auto& x, auto& f) {
    f.resize(2);
    f[0] = x[0] - x[1];
    f[1] = x[1] - x[0] + 1.0;
  };
  const RootProblem<> problem = sparse_autodiff_problem(singular, Vector<Dynamic>::Zero(2));
  for (const std::string linear : {"band-lu", "sparse-lu", "klu", "gmres"}) {
    Vector<Dynamic> x = Vector<Dynamic>::Zero(2);
    const Summary s = solve_with(linear, problem, x);
    // A Krylov breakdown is the solver's failure (BiCGSTAB breaks down on regular J too).
    EXPECT_EQ(s.status, linear == "gmres" ? Status::kSolverFailure : Status::kSingularJacobian)
        << linear << ": " << s.message;
    EXPECT_NE(s.message.find(linear), std::string::npos) << s.message;
    EXPECT_TRUE(x.allFinite());
  }
}

// Modified Newton (KINSOL's default): one Jacobian and its factorisation for several steps,
// renewed when a step no longer halves ‖F‖₂. The same root as Newton, with fewer Jacobians and
// factorisations than iterations; KLU and GMRES alike; and on the dense path too.
TEST(SparseNewton, ModifiedNewtonReusesTheFactorisationAndReachesTheSameRoot) {
  const Index s = 30;
  const Vector<Dynamic> x0 = Vector<Dynamic>::Zero(s * s);
  const RootProblem<> problem = sparse_autodiff_problem(bratu(s), x0);
  Vector<Dynamic> newton_root = x0;
  const Summary exact = solve_with("klu", problem, newton_root);
  ASSERT_EQ(exact.status, Status::kConverged) << exact.message;
  EXPECT_EQ(exact.jacobian_evaluations, exact.iterations);
  for (const std::string linear : {"klu", "gmres:preconditioner=ilu0"}) {
    SCOPED_TRACE(linear);
    for (const int reuse : {10, 1000}) {
      NewtonEngine<> modified(
          NewtonOptions{.line_search = true, .linear_solver = linear, .jacobian_reuse = reuse},
          test::residual_stop());
      Vector<Dynamic> x = x0;
      const Summary m = modified.solve(to_fixed_point(problem), x);
      ASSERT_EQ(m.status, Status::kConverged) << m.message;
      // Only a fresh Jacobian's step may stop the run on the step test: a stale one's small
      // step says little of the distance to the root (linear convergence).
      EXPECT_LE(m.residual_norm, 1e-10);
      EXPECT_LT(m.jacobian_evaluations, m.iterations) << reuse;
      EXPECT_GE(m.jacobian_evaluations, 1);
      EXPECT_EQ(m.linear_setups, m.jacobian_evaluations);  // one factorisation per Jacobian
      EXPECT_LE((x - newton_root).lpNorm<Eigen::Infinity>(), 1e-8);
    }
  }
  // The dense path (a problem without a sparse Jacobian) reuses its LU the same way.
  const auto dense_problem =
      to_fixed_point(RootProblem<>::with_autodiff(bratu(8), 64, 64).with_dense_jacobian());
  NewtonEngine<> dense(NewtonOptions{.line_search = true, .jacobian_reuse = 10},
                       test::residual_stop());
  Vector<Dynamic> x = Vector<Dynamic>::Zero(64);
  const Summary d = dense.solve(dense_problem, x);
  ASSERT_EQ(d.status, Status::kConverged) << d.message;
  EXPECT_TRUE(d.linear_solver.empty());
  EXPECT_LT(d.jacobian_evaluations, d.iterations);
}

// A stale Jacobian is renewed when its steps stop working: atan's slope at x0 = 1.2 is 0.41, at
// the root 1, so J frozen at x0 overshoots near the root; modified Newton still converges (12
// iterations on 3 Jacobians; Newton: 5 on 5), with more than one Jacobian and fewer than its
// iterations. (From 1.5 Newton itself stagnates, as atan's Newton does beyond 1.39.)
TEST(SparseNewton, ModifiedNewtonRenewsAStaleJacobianItCannotUse) {
  auto atan_chain = [](const auto& x, auto& f) {
    using std::atan;
    for (Index i = 0; i < x.size(); ++i) {
      f[i] = atan(x[i]) + (i > 0 ? 0.1 * x[i - 1] : 0.0 * x[i]);
    }
  };
  const Vector<Dynamic> x0 = Vector<Dynamic>::Constant(200, 1.2);
  const RootProblem<> problem = sparse_autodiff_problem(atan_chain, x0);
  NewtonEngine<> modified(NewtonOptions{.line_search = true, .jacobian_reuse = 1000},
                          test::residual_stop());
  Vector<Dynamic> x = x0;
  const Summary m = modified.solve(to_fixed_point(problem), x);
  ASSERT_EQ(m.status, Status::kConverged) << m.message;
  EXPECT_GT(m.jacobian_evaluations, 1);
  EXPECT_LT(m.jacobian_evaluations, m.iterations);
  EXPECT_LE(x.lpNorm<Eigen::Infinity>(), 1e-9);
  // Without a line search a stale step must lower |F|2, or J is renewed: from 1.2 as above.
  NewtonEngine<> plain(NewtonOptions{.jacobian_reuse = 1000}, test::residual_stop());
  x = x0;
  const Summary p = plain.solve(to_fixed_point(problem), x);
  ASSERT_EQ(p.status, Status::kConverged) << p.message;
  EXPECT_GT(p.jacobian_evaluations, 1);
  EXPECT_LE(x.lpNorm<Eigen::Infinity>(), 1e-9);
  EXPECT_THROW(NewtonEngine<>(NewtonOptions{.jacobian_reuse = 0}), InvalidInput);
  EXPECT_THROW(NewtonEngine<>(NewtonOptions{.jacobian_reuse = 1001}), InvalidInput);
  EXPECT_NE(test::message_of([] {
              NewtonEngine<>(NewtonOptions{.trust_region = true, .jacobian_reuse = 10});
            }).find("trust region"),
            std::string::npos);
  EXPECT_THROW(EngineRegistry<Dynamic>::global().create("newton:reuse=0"), InvalidInput);
  EXPECT_EQ(EngineRegistry<Dynamic>::global().create("newton:linesearch=1,reuse=10")->name(),
            "newton");
}

// In a box that holds the root out (atan(x_i) + 0.1 x_{i−1} = 0.8 has its root near 0.9, the box
// stops at 0.5), the verdict blocked_by_bound is judged at a fresh Jacobian: the stale one's
// failed search renews J at once instead of judging the descent direction by it.
TEST(SparseNewton, ModifiedNewtonJudgesABlockingBoundAtAFreshJacobian) {
  auto shifted_atan_chain = [](const auto& x, auto& f) {
    using std::atan;
    for (Index i = 0; i < x.size(); ++i) {
      f[i] = atan(x[i]) + (i > 0 ? 0.1 * x[i - 1] : 0.0 * x[i]) - 0.8;
    }
  };
  const Vector<Dynamic> x0 = Vector<Dynamic>::Zero(200);
  const RootProblem<> problem = sparse_autodiff_problem(shifted_atan_chain, x0);
  for (const int reuse : {1, 10}) {
    NewtonEngine<> engine(NewtonOptions{.line_search = true, .jacobian_reuse = reuse},
                          test::residual_stop());
    engine.set_bounds({Vector<Dynamic>::Constant(200, -10.0), Vector<Dynamic>::Constant(200, 0.5)});
    Vector<Dynamic> x = x0;
    const Summary s = engine.solve(to_fixed_point(problem), x);
    EXPECT_EQ(s.status, Status::kBlockedByBound) << reuse << ": " << s.message;
    EXPECT_GE(s.jacobian_evaluations, 2) << reuse;
    EXPECT_LE(x.maxCoeff(), 0.5);
  }
}

TEST(SparseNewton, IsReachableByEngineSpecAndRefusesBadSpecs) {
  const Vector<Dynamic> x0 = Vector<Dynamic>::Constant(50, -1.0);
  const RootProblem<> problem = sparse_autodiff_problem(broyden_tridiagonal(), x0);
  auto engine = EngineRegistry<Dynamic>::global().create(
      "newton:linesearch=1,linear=bicgstab,preconditioner=jacobi", test::residual_stop());
  Vector<Dynamic> x = x0;
  const Summary s = engine->solve(to_fixed_point(problem), x);
  ASSERT_EQ(s.status, Status::kConverged) << s.message;
  EXPECT_EQ(s.linear_solver, "bicgstab");
  EXPECT_THROW(EngineRegistry<Dynamic>::global().create("newton:linear=cholesky"), InvalidInput);
  EXPECT_NE(test::message_of([] {
              EngineRegistry<Dynamic>::global().create("newton:linear=cholesky");
            }).find("(or auto, dense)"),
            std::string::npos);
  EXPECT_THROW(EngineRegistry<Dynamic>::global().create("newton:preconditioner=ilu0"),
               InvalidInput);
  EXPECT_THROW(EngineRegistry<Dynamic>::global().create("newton:linear=klu,preconditioner=ilu0"),
               InvalidInput);
  EXPECT_THROW(NewtonEngine<>(NewtonOptions{.forcing = {.maximum = 2.0}}), InvalidInput);
}

TEST(SparseProblem, AddsTheDiagonalAndRefusesABranchingF) {
  // F_i = x_{i+1} (no diagonal): the pattern gets it, so ILU(0) and the pivots have one.
  auto shift = [](const auto& x, auto& f) {
    f.resize(x.size());
    for (Index i = 0; i < x.size(); ++i) f[i] = x[(i + 1) % x.size()] - 1.0;
  };
  const RootProblem<> problem = sparse_autodiff_problem(shift, Vector<Dynamic>::Zero(5));
  const SparsityPattern& pattern = *problem.sparse_jacobian()->pattern;
  for (Index i = 0; i < 5; ++i) EXPECT_TRUE(pattern.contains(i, i)) << i;
  EXPECT_EQ(pattern.nonzeros(), 10);
  Vector<Dynamic> root = Vector<Dynamic>::Zero(5);
  EXPECT_EQ(solve_with("klu", problem, root).status, Status::kConverged);
  EXPECT_LE((root - Vector<Dynamic>::Ones(5)).norm(), 1e-12);
  // ILU(0) meets the zero diagonal: a named solver failure, not a singular J.
  root.setZero();
  const Summary s = solve_with("gmres:preconditioner=ilu0", problem, root);
  EXPECT_EQ(s.status, Status::kSolverFailure);
  EXPECT_NE(s.message.find("ilu0: row 0: zero pivot"), std::string::npos) << s.message;

  auto branching = [](const auto& x, auto& f) {
    f.resize(x.size());
    for (Index i = 0; i < x.size(); ++i) f[i] = x[i] > 0.0 ? x[i] : -x[i];
  };
  EXPECT_THROW(sparse_autodiff_problem(branching, Vector<Dynamic>::Ones(3)), InvalidInput);
}

}  // namespace
}  // namespace nlobs
