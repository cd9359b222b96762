// Sparsity detection for an unchanged RootProblem::with_autodiff at run-time size
// (sparse/sparsity_detection.hpp): Newton takes the sparse path on a detected pattern and ends
// where the declared pattern does; each rule that declines (size, branches, dense rows, the trace
// budget, non-square F) keeps the dense path and says why; detection runs once for all copies, is
// switched off by with_dense_jacobian() and by linear_solver = "dense", and survives an F that
// throws while traced.
#include <gtest/gtest.h>

#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "large_test_problems.hpp"
#include "nlobs/solvers/builtin_engines.hpp"
#include "nlobs/solvers/engine_registry.hpp"
#include "nlobs/solvers/newton_engine.hpp"
#include "nlobs/solvers/root_adapter.hpp"
#include "nlobs/solvers/sparse/sparse_problem.hpp"
#include "test_support.hpp"

namespace nlobs {
namespace {

using test::broyden_tridiagonal;

Summary newton(const RootProblem<>& problem, Vector<Dynamic>& x, NewtonOptions options = {}) {
  NewtonEngine<> engine(options, test::residual_stop());
  return engine.solve(to_fixed_point(problem), x);
}

bool starts_with(const std::string& text, const std::string& prefix) {
  return text.rfind(prefix, 0) == 0;
}

TEST(SparsityDetection, GivesAnUnchangedWithAutodiffProblemTheSparsePath) {
  const Index n = 2000;
  const Vector<Dynamic> x0 = Vector<Dynamic>::Constant(n, -1.0);
  const auto problem = RootProblem<>::with_autodiff(broyden_tridiagonal(), n, n);
  EXPECT_EQ(problem.sparse_jacobian(), nullptr) << "detection waits for a point";
  EXPECT_TRUE(starts_with(problem.sparse_jacobian_note(), "not detected yet"))
      << problem.sparse_jacobian_note();

  Vector<Dynamic> detected = x0;
  const Summary s = newton(problem, detected);
  ASSERT_EQ(s.status, Status::kConverged) << s.message;
  EXPECT_EQ(s.linear_solver, "band-lu");
  ASSERT_NE(problem.sparse_jacobian(), nullptr) << "the copy's detection is the problem's";
  EXPECT_EQ(problem.sparse_jacobian()->pattern->nonzeros(), 3 * n - 2);
  EXPECT_TRUE(starts_with(problem.sparse_jacobian_note(), "detected"))
      << problem.sparse_jacobian_note();

  // The declared pattern: the same iterations, the same root.
  Vector<Dynamic> declared = x0;
  const Summary d = newton(sparse_autodiff_problem(broyden_tridiagonal(), x0), declared);
  ASSERT_EQ(d.status, Status::kConverged) << d.message;
  EXPECT_EQ(s.iterations, d.iterations);
  EXPECT_EQ(s.jacobian_evaluations, d.jacobian_evaluations);
  EXPECT_LE((detected - declared).lpNorm<Eigen::Infinity>(), 1e-14);

  // And by name, as a user of the registry or the CLI reaches it.
  auto by_name = EngineRegistry<Dynamic>::global().create("newton", test::residual_stop());
  Vector<Dynamic> x = x0;
  const Summary r =
      by_name->solve(to_fixed_point(RootProblem<>::with_autodiff(broyden_tridiagonal(), n, n)), x);
  ASSERT_EQ(r.status, Status::kConverged) << r.message;
  EXPECT_EQ(r.linear_solver, "band-lu");
}

TEST(SparsityDetection, MatchesTheDensePathFromTheSmallestSizeUp) {
  for (const Index n : {Index{99}, SparsityDetectionRule::kSmallestSize}) {
    const Vector<Dynamic> x0 = Vector<Dynamic>::Constant(n, -1.0);
    const auto problem = RootProblem<>::with_autodiff(broyden_tridiagonal(), n, n);
    Vector<Dynamic> x = x0, dense = x0;
    const Summary s = newton(problem, x);
    const Summary reference = newton(problem.with_dense_jacobian(), dense);
    ASSERT_EQ(s.status, Status::kConverged) << s.message;
    EXPECT_EQ(s.iterations, reference.iterations) << n;
    EXPECT_LE((x - dense).lpNorm<Eigen::Infinity>(), 1e-12) << n;
    EXPECT_TRUE(reference.linear_solver.empty());
    if (n < SparsityDetectionRule::kSmallestSize) {
      EXPECT_TRUE(s.linear_solver.empty()) << n;
      EXPECT_NE(problem.sparse_jacobian_note().find("is below 100"), std::string::npos)
          << problem.sparse_jacobian_note();
    } else {
      EXPECT_EQ(s.linear_solver, "band-lu") << n;
    }
  }
}

// F_i = x_i − 1 where x_i > 0, else 2x_i − 1 + x_{i+1}: the branch hides a pattern.
auto branching() {
  return [](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    const Index n = x.size();
    Vector<Dynamic, T> f(n);
    for (Index i = 0; i < n; ++i) {
      f[i] = x[i] > 0.0 ? x[i] - 1.0 : 2.0 * x[i] - 1.0 + (i + 1 < n ? x[i + 1] : T(0.0));
    }
    return f;
  };
}

// F_i = x_i − 1 + 10⁻³ Σ_j x_j: every row dense.
auto dense_rows() {
  return [](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    T sum(0.0);
    for (Index j = 0; j < x.size(); ++j) sum += x[j];
    Vector<Dynamic, T> f(x.size());
    for (Index i = 0; i < x.size(); ++i) f[i] = x[i] - 1.0 + 1e-3 * sum;
    return f;
  };
}

TEST(SparsityDetection, KeepsTheDensePathWhereFBranchesOrJIsDense) {
  const Index n = 200;
  {
    const auto problem = RootProblem<>::with_autodiff(branching(), n, n);
    Vector<Dynamic> x = Vector<Dynamic>::Constant(n, 0.5);
    const Summary s = newton(problem, x);
    ASSERT_EQ(s.status, Status::kConverged) << s.message;
    EXPECT_TRUE(s.linear_solver.empty());
    EXPECT_EQ(problem.sparse_jacobian(), nullptr);
    EXPECT_NE(problem.sparse_jacobian_note().find("compared a value that depends on x (200"),
              std::string::npos)
        << problem.sparse_jacobian_note();
  }
  {
    const auto problem = RootProblem<>::with_autodiff(dense_rows(), n, n);
    Vector<Dynamic> x = Vector<Dynamic>::Zero(n);
    const Summary s = newton(problem, x);
    ASSERT_EQ(s.status, Status::kConverged) << s.message;
    EXPECT_TRUE(s.linear_solver.empty());
    EXPECT_NE(problem.sparse_jacobian_note().find("more than 20 entries"), std::string::npos)
        << problem.sparse_jacobian_note();
    EXPECT_NEAR(x[0], 1.0 / 1.2, 1e-12);
  }
  // The trace's limits end with it: this thread's limits are the unbounded defaults again, and a
  // detection afterwards sees every entry.
  EXPECT_FALSE(detail::SparsityTracerLimits.exceeded);
  EXPECT_EQ(detail::SparsityTracerLimits.largest_set, detail::SparsityTraceLimits{}.largest_set);
  EXPECT_EQ(detail::SparsityTracerLimits.budget, detail::SparsityTraceLimits{}.budget);
  auto f = dense_rows();
  EXPECT_EQ(detect_sparsity(f, Vector<Dynamic>::Zero(n)).nonzeros(), n * n);
}

TEST(SparsityDetection, StopsATraceAtItsBudgetAndLargestSet) {
  auto f = broyden_tridiagonal();
  const Vector<Dynamic> x = Vector<Dynamic>::Zero(50);
  const detail::SparsityTrace full = detail::trace_sparsity(f, x, Dynamic, {});
  EXPECT_FALSE(full.exceeded);
  EXPECT_EQ(full.pattern.nonzeros(), 3 * 50 - 2);
  EXPECT_TRUE(detail::trace_sparsity(f, x, Dynamic, {.budget = 100}).exceeded);
  EXPECT_TRUE(detail::trace_sparsity(f, x, Dynamic, {.largest_set = 2}).exceeded);
  EXPECT_FALSE(detail::trace_sparsity(f, x, Dynamic, {.largest_set = 3}).exceeded);
}

TEST(SparsityDetection, IsSwitchedOffByDenseJacobianOrDenseLinearSolver) {
  const Index n = 300;
  const Vector<Dynamic> x0 = Vector<Dynamic>::Constant(n, -1.0);
  const auto off = RootProblem<>::with_autodiff(broyden_tridiagonal(), n, n).with_dense_jacobian();
  EXPECT_EQ(off.sparse_jacobian_note(), "");
  EXPECT_EQ(off.sparse_jacobian(x0), nullptr);
  Vector<Dynamic> x = x0;
  EXPECT_TRUE(newton(off, x).linear_solver.empty());

  const auto problem = RootProblem<>::with_autodiff(broyden_tridiagonal(), n, n);
  x = x0;
  const Summary s = newton(problem, x, NewtonOptions{.linear_solver = "dense"});
  ASSERT_EQ(s.status, Status::kConverged);
  EXPECT_TRUE(s.linear_solver.empty());
  EXPECT_TRUE(starts_with(problem.sparse_jacobian_note(), "not detected yet"))
      << "linear_solver = dense runs no detection";
}

TEST(SparsityDetection, LeavesTheTrustRegionOnTheDensePathButRefusesItForADeclaredPattern) {
  const Index n = 300;
  const Vector<Dynamic> x0 = Vector<Dynamic>::Constant(n, -1.0);
  NewtonOptions trust{.line_search = false, .trust_region = true};
  Vector<Dynamic> x = x0;
  const Summary s = newton(RootProblem<>::with_autodiff(broyden_tridiagonal(), n, n), x, trust);
  ASSERT_EQ(s.status, Status::kConverged) << s.message;
  EXPECT_TRUE(s.linear_solver.empty());
  x = x0;
  EXPECT_THROW(newton(sparse_autodiff_problem(broyden_tridiagonal(), x0), x, trust), InvalidInput);
}

TEST(SparsityDetection, DetectsATallFAndDeclinesAWideOne) {
  // m > n (least squares: levenberg-marquardt's sparse path) is detected; m < n has no engine.
  const Index n = 150;
  auto tall = [](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    Vector<Dynamic, T> r(x.size() + 1);
    r.head(x.size()) = x;
    r[x.size()] = x[0] + x[x.size() - 1];
    return r;
  };
  const auto problem = RootProblem<>::with_autodiff(tall, n, n + 1);
  const SparseJacobianSource* source = problem.sparse_jacobian(Vector<Dynamic>::Zero(n));
  ASSERT_NE(source, nullptr) << problem.sparse_jacobian_note();
  EXPECT_EQ(source->pattern->rows, n + 1);
  EXPECT_EQ(source->pattern->cols, n);
  EXPECT_TRUE(source->pattern->contains(n, 0) && source->pattern->contains(n, n - 1));
  EXPECT_EQ(problem.sparse_jacobian_note(), "detected: " + std::to_string(n + 2) + " entries");

  auto wide = [](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    Vector<Dynamic, T> r(x.size() - 1);
    for (Index i = 0; i + 1 < x.size(); ++i) r[i] = x[i] - x[i + 1];
    return r;
  };
  const auto underdetermined = RootProblem<>::with_autodiff(wide, n, n - 1);
  EXPECT_EQ(underdetermined.sparse_jacobian(Vector<Dynamic>::Zero(n)), nullptr);
  EXPECT_NE(underdetermined.sparse_jacobian_note().find("fewer residuals than unknowns"),
            std::string::npos)
      << underdetermined.sparse_jacobian_note();
}

TEST(SparsityDetection, DeclinesWhereFThrowsWhileTracedAndLeavesNoCountBehind) {
  const Index n = 150;
  auto f = [](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    if constexpr (std::is_same_v<T, SparsityTracer>) {
      T partial = x[0] + x[1];
      if (partial > 0.0) partial = -partial;  // (a branch counted before F throws)
      throw std::runtime_error("F refuses tracers");
    }
    Vector<Dynamic, T> r(x.size());
    for (Index i = 0; i < x.size(); ++i) r[i] = x[i] - 1.0;
    return r;
  };
  const auto problem = RootProblem<>::with_autodiff(f, n, n);
  Vector<Dynamic> x = Vector<Dynamic>::Zero(n);
  const Summary s = newton(problem, x);
  ASSERT_EQ(s.status, Status::kConverged) << s.message;
  EXPECT_TRUE(s.linear_solver.empty()) << "the dense path, as before detection";
  EXPECT_EQ(problem.sparse_jacobian_note(),
            "not detected: F threw while traced: F refuses tracers");
  // The thrown trace left this thread's counters and limits as they were before it.
  EXPECT_EQ(detail::SparsityTracerBranches, 0);
  EXPECT_FALSE(detail::SparsityTracerLimits.exceeded);
  EXPECT_EQ(detail::SparsityTracerLimits.budget, detail::SparsityTraceLimits{}.budget);
  // Also when the trace had limits and went past them.
  EXPECT_THROW(detail::trace_sparsity(f, x, Dynamic, {.largest_set = 1, .budget = 1}),
               std::runtime_error);
  EXPECT_EQ(detail::SparsityTracerBranches, 0);
  EXPECT_FALSE(detail::SparsityTracerLimits.exceeded);
  EXPECT_EQ(detail::SparsityTracerLimits.largest_set, detail::SparsityTraceLimits{}.largest_set);
}

TEST(SparsityDetection, ReachesAHundredThousandUnknownsFromUnchangedCode) {
  // A dense path here would need an 80 GB Jacobian: only the detected sparse path finishes.
  const Index n = 100000;
  const auto problem = RootProblem<>::with_autodiff(broyden_tridiagonal(), n, n);
  Vector<Dynamic> x = Vector<Dynamic>::Constant(n, -1.0);
  const Summary s = newton(problem, x, NewtonOptions{.line_search = true});
  ASSERT_EQ(s.status, Status::kConverged) << s.message;
  EXPECT_EQ(s.linear_solver, "band-lu");
  EXPECT_LE(s.residual_norm, 1e-10);
  EXPECT_EQ(problem.sparse_jacobian_note(), "detected: 299998 entries");
}

TEST(SparsityDetection, DetectsNothingFromANonFiniteStart) {
  // x0 is refused before detection: the problem keeps detection to do for a good start.
  const Index n = 200;
  const auto problem = RootProblem<>::with_autodiff(broyden_tridiagonal(), n, n);
  Vector<Dynamic> x = Vector<Dynamic>::Constant(n, -1.0);
  x[7] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(newton(problem, x), InvalidInput);
  EXPECT_TRUE(starts_with(problem.sparse_jacobian_note(), "not detected yet"))
      << problem.sparse_jacobian_note();
  x.setConstant(-1.0);
  ASSERT_EQ(newton(problem, x).status, Status::kConverged);
  EXPECT_TRUE(starts_with(problem.sparse_jacobian_note(), "detected"));
}

TEST(SparsityDetection, RefusesAPointOfAnotherSize) {
  const auto problem = RootProblem<>::with_autodiff(broyden_tridiagonal(), 200, 200);
  EXPECT_THROW(problem.sparse_jacobian(Vector<Dynamic>::Zero(199)), InvalidInput);
  EXPECT_TRUE(starts_with(problem.sparse_jacobian_note(), "not detected yet"));
}

}  // namespace
}  // namespace nlobs
