// Broyden's method in limited-memory form (the sparse path: H_0 applied by a sparse direct
// solver, the updates kept as vectors) against the dense path that stores H, on problems nlobs
// does not ship: Broyden's tridiagonal function, 2-D Bratu, F = x² (a singular J at 0); the
// restarts `memory` forces, a binding box, a scaling, and bad options.
#include <gtest/gtest.h>

#include <string>

#include "invalid_argument_message.hpp"
#include "large_test_problems.hpp"
#include "nlobs/solvers/broyden_engine.hpp"
#include "nlobs/solvers/builtin_engines.hpp"
#include "nlobs/solvers/engine_registry.hpp"
#include "nlobs/solvers/root_adapter.hpp"
#include "nlobs/solvers/sparse/sparse_problem.hpp"
#include "short_tests.hpp"

namespace nlobs {
namespace {

Summary broyden(const BroydenOptions& options, const RootProblem<>& problem, Vector<Dynamic>& x,
                const BoxBounds& box = {}, const Scaling& scaling = {}) {
  BroydenEngine<> engine(options, test::residual_stop(1e-10, 300));
  if (box.lower.size() != 0 || box.upper.size() != 0) engine.set_bounds(box);
  if (!scaling.empty()) engine.set_scaling(scaling);
  return engine.solve(to_fixed_point(problem), x);
}

// The same iterates: both converge with the same counts and answers within rounding.
void expect_same_run(const Summary& limited, const Vector<Dynamic>& x, const Summary& dense,
                     const Vector<Dynamic>& x_dense, const std::string& label) {
  ASSERT_EQ(dense.status, Status::kConverged) << label << ": " << dense.full_report();
  ASSERT_EQ(limited.status, Status::kConverged) << label << ": " << limited.full_report();
  EXPECT_TRUE(dense.linear_solver.empty()) << label;
  EXPECT_FALSE(limited.linear_solver.empty()) << label;
  EXPECT_EQ(limited.iterations, dense.iterations) << label;
  EXPECT_EQ(limited.function_evaluations, dense.function_evaluations) << label;
  EXPECT_EQ(limited.jacobian_evaluations, dense.jacobian_evaluations) << label;
  EXPECT_LE((x - x_dense).lpNorm<Eigen::Infinity>(), 1e-9) << label;
}

TEST(LimitedMemoryBroyden, TakesTheDensePathsIteratesOnBroydenTridiagonal) {
  const Index n = 300;  // detected (n ≥ 100)
  const Vector<Dynamic> x0 = Vector<Dynamic>::Constant(n, -1.0);
  const auto problem = RootProblem<>::with_autodiff(test::broyden_tridiagonal(), n, n);
  Vector<Dynamic> x = x0, x_dense = x0;
  const Summary dense = broyden({.linear_solver = "dense"}, problem, x_dense);
  const Summary limited = broyden({}, problem, x);
  expect_same_run(limited, x, dense, x_dense, "default memory");
  EXPECT_EQ(limited.linear_solver, "band-lu");
  EXPECT_EQ(limited.linear_setups, limited.jacobian_evaluations);
  EXPECT_GT(limited.iterations, limited.jacobian_evaluations) << "updates, not Newton steps";

  // memory = 2 restarts after every second update, as updates = 2 does on the dense path.
  x = x0, x_dense = x0;
  const Summary dense2 = broyden({.max_updates = 2, .linear_solver = "dense"}, problem, x_dense);
  const Summary limited2 = broyden({.linear_solver = "klu", .memory = 2}, problem, x);
  expect_same_run(limited2, x, dense2, x_dense, "memory 2");
  EXPECT_EQ(limited2.linear_solver, "klu");
  EXPECT_GT(limited2.jacobian_evaluations, limited.jacobian_evaluations);

  // memory 3 with max_updates 2: the smaller limit restarts; one engine solving twice.
  BroydenEngine<> engine({.max_updates = 2, .memory = 3}, test::residual_stop(1e-10, 300));
  x_dense = x0;
  ASSERT_EQ(broyden({.max_updates = 2, .linear_solver = "dense"}, problem, x_dense).iterations,
            dense2.iterations);
  for (int run = 0; run < 2; ++run) {
    x = x0;
    const Summary limited3 = engine.solve(to_fixed_point(problem), x);
    expect_same_run(limited3, x, dense2, x_dense,
                    "max_updates 2, memory 3, run " + std::to_string(run));
  }
}

TEST(LimitedMemoryBroyden, ARunLongerThanItsMemoryRestartsAsMaxUpdatesDoes) {
  // Bratu from 0 with memory 1: a fresh Jacobian after every update, as updates = 1 densely;
  // coloured differences (F on doubles) instead of AD.
  const Index s = 15, n = s * s;
  const auto f = test::bratu(s);
  const SparsityPattern pattern = detect_sparsity(f, Vector<Dynamic>::Zero(n), n);
  const RootProblem<> problem = sparse_difference_problem(
      [f](const Vector<Dynamic>& u, Vector<Dynamic>& out) mutable { f(u, out); }, pattern);
  Vector<Dynamic> x = Vector<Dynamic>::Zero(n), x_dense = x;
  const Summary dense = broyden({.max_updates = 1, .linear_solver = "dense"}, problem, x_dense);
  const Summary limited = broyden({.linear_solver = "umfpack", .memory = 1}, problem, x);
  ASSERT_EQ(dense.status, Status::kConverged) << dense.full_report();
  ASSERT_EQ(limited.status, Status::kConverged) << limited.full_report();
  EXPECT_EQ(limited.linear_solver, "umfpack");
  EXPECT_EQ(limited.iterations, dense.iterations);
  EXPECT_EQ(limited.jacobian_evaluations, dense.jacobian_evaluations);
  EXPECT_GT(limited.jacobian_evaluations, 1);
  EXPECT_LE((x - x_dense).lpNorm<Eigen::Infinity>(), 1e-8);
}

TEST(LimitedMemoryBroyden, KeepsABindingBoxAndAScalingAsTheDensePathDoes) {
  const Index n = 120;
  const Vector<Dynamic> x0 = Vector<Dynamic>::Constant(n, -1.0);
  const RootProblem<> problem = sparse_autodiff_problem(test::broyden_tridiagonal(), x0);
  Vector<Dynamic> root = x0;
  ASSERT_EQ(broyden({}, problem, root).status, Status::kConverged);
  // A box through the root: the answer is not a root; both paths end the same way.
  const double upper = 0.5 * (root.minCoeff() + root.maxCoeff());
  const BoxBounds box{Vector<Dynamic>::Constant(n, -2.0), Vector<Dynamic>::Constant(n, upper)};
  Vector<Dynamic> x = x0, x_dense = x0;
  const Summary dense = broyden({.linear_solver = "dense"}, problem, x_dense, box);
  const Summary limited = broyden({}, problem, x, box);
  EXPECT_EQ(limited.status, dense.status) << limited.message << " / " << dense.message;
  EXPECT_EQ(limited.linear_solver, "band-lu");
  EXPECT_EQ(limited.iterations, dense.iterations);
  EXPECT_EQ(limited.function_evaluations, dense.function_evaluations);
  EXPECT_EQ(limited.jacobian_evaluations, dense.jacobian_evaluations);
  EXPECT_LE((x - x_dense).lpNorm<Eigen::Infinity>(), 1e-9);
  EXPECT_LE(x.maxCoeff(), upper);

  Vector<Dynamic> scale(n);
  for (Index i = 0; i < n; ++i) scale[i] = i % 2 == 0 ? 1e3 : 1e-2;
  const Scaling scaling{.u_scale = scale, .f_scale = scale.cwiseInverse()};
  x = x0, x_dense = x0;
  const Summary dense_scaled = broyden({.linear_solver = "dense"}, problem, x_dense, {}, scaling);
  const Summary limited_scaled = broyden({}, problem, x, {}, scaling);
  expect_same_run(limited_scaled, x, dense_scaled, x_dense, "scaled");
}

TEST(LimitedMemoryBroyden, SolvesBratuAndLargeTridiagonalSystemsOnTheSparsePath) {
  const Index s = 60, n = s * s;
  Vector<Dynamic> u = Vector<Dynamic>::Zero(n);
  const Summary bratu = broyden({}, RootProblem<>::with_autodiff(test::bratu(s), n, n), u);
  ASSERT_EQ(bratu.status, Status::kConverged) << bratu.full_report();
  EXPECT_EQ(bratu.linear_solver, "klu");

  // (2·10⁴ unknowns under the sanitizers, NLOBS_SHORT_TESTS: the same path.)
  const Index large = test::short_tests() ? 20000 : 200000;
  Vector<Dynamic> x = Vector<Dynamic>::Constant(large, -1.0);
  const Summary tridiagonal =
      broyden({}, RootProblem<>::with_autodiff(test::broyden_tridiagonal(), large, large), x);
  ASSERT_EQ(tridiagonal.status, Status::kConverged) << tridiagonal.full_report();
  EXPECT_EQ(tridiagonal.linear_solver, "band-lu");
  const Vector<Dynamic> f = test::broyden_tridiagonal()(x);
  EXPECT_LE(f.lpNorm<Eigen::Infinity>(), 1e-6) << tridiagonal.full_report();
  EXPECT_DOUBLE_EQ(f.lpNorm<Eigen::Infinity>(), tridiagonal.residual_norm);
}

TEST(LimitedMemoryBroyden, NamesASingularJacobian) {
  const Index n = 150;
  auto squares = [](const auto& x, auto& f) { f = x.cwiseProduct(x); };  // J = 2 diag(x) = 0 at 0
  Vector<Dynamic> x = Vector<Dynamic>::Zero(n);
  x[0] = 1.0;  // (F ≠ 0 at the start, so that a step is needed)
  const Summary s = broyden({}, RootProblem<>::with_autodiff(squares, n, n), x);
  EXPECT_EQ(s.status, Status::kSingularJacobian) << s.full_report();
  EXPECT_NE(s.message.find("singular"), std::string::npos) << s.message;
  EXPECT_EQ(s.linear_solver, "band-lu");
}

TEST(LimitedMemoryBroyden, RefusesOptionsItCannotHonour) {
  EXPECT_NE(test::invalid_argument_of([] {
              BroydenEngine<>({.memory = 0});
            }).find("BroydenOptions::memory = 0 is invalid"),
            std::string::npos);
  EXPECT_NE(test::invalid_argument_of([] {
              BroydenEngine<>({.linear_solver = "gmres"});
            }).find("must be applied exactly"),
            std::string::npos);
  EXPECT_NE(test::invalid_argument_of([] {
              BroydenEngine<>({.linear_solver = "lu"});
            }).find("BroydenOptions::linear_solver"),
            std::string::npos);
  auto& registry = EngineRegistry<Dynamic>::global();
  EXPECT_NO_THROW(registry.create("broyden:memory=5,linear=klu", {}));
  EXPECT_NO_THROW(registry.create("broyden:linear=umfpack,ordering=metis", {}));
  EXPECT_NE(
      test::invalid_argument_of([&] { registry.create("broyden:memory=0", {}); }).find("memory"),
      std::string::npos);
  EXPECT_NE(test::invalid_argument_of([&] {
              registry.create("broyden:preconditioner=ilu0", {});
            }).find("does not apply"),
            std::string::npos);
  EXPECT_TRUE(BroydenEngine<>().has_sparse_path());
  EXPECT_FALSE(BroydenEngine<>({.linear_solver = "dense"}).has_sparse_path());
}

}  // namespace
}  // namespace nlobs
