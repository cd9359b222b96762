// hypre's BoomerAMG as the Krylov preconditioner (nlobs/solvers/linear/boomeramg.hpp), on
// operators nlobs does not ship: the 2-D Laplacian (its GMRES iterations must stay flat as the
// grid is refined, where ILU(0)'s grow), an upwind convection–diffusion operator (nonsymmetric),
// 2-D Bratu through Newton; and its failures: a NaN in J, J not square, a zero row, apply before
// setup, invalid options and specs, two threads at once.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "large_test_problems.hpp"
#include "nlobs/common/invalid_input.hpp"
#include "nlobs/solvers/linear/boomeramg.hpp"
#include "nlobs/solvers/linear/gmres.hpp"
#include "nlobs/solvers/linear/make_linear_solver.hpp"
#include "nlobs/solvers/linear/preconditioners.hpp"
#include "nlobs/solvers/newton_engine.hpp"
#include "nlobs/solvers/root_adapter.hpp"
#include "nlobs/solvers/sparse/sparse_problem.hpp"

namespace nlobs {
namespace {

using Triplets = std::vector<Eigen::Triplet<double>>;

// (convection · ∇ − Δ) on an s×s grid, h = 1/(s+1), Dirichlet boundary, the convection term by
// first-order upwind differences (nonsymmetric for convection ≠ 0); scaled by h².
SparseJacobian convection_diffusion(Index s, double convection) {
  const double h = 1.0 / static_cast<double>(s + 1);
  Triplets entries;
  for (Index r = 0; r < s; ++r) {
    for (Index c = 0; c < s; ++c) {
      const Index p = r * s + c;
      entries.emplace_back(p, p, 4.0 + convection * h);
      if (r > 0) entries.emplace_back(p, p - s, -1.0);
      if (r + 1 < s) entries.emplace_back(p, p + s, -1.0);
      if (c > 0) entries.emplace_back(p, p - 1, -1.0 - convection * h);
      if (c + 1 < s) entries.emplace_back(p, p + 1, -1.0);
    }
  }
  SparseJacobian jac(s * s, s * s);
  jac.setFromTriplets(entries.begin(), entries.end());
  jac.makeCompressed();
  return jac;
}

Vector<Dynamic> smooth_rhs(Index n) {
  Vector<Dynamic> b(n);
  for (Index i = 0; i < n; ++i) b[i] = std::sin(0.37 * static_cast<double>(i)) + 1.0;
  return b;
}

double relative_residual(const SparseJacobian& jac, const Vector<Dynamic>& x,
                         const Vector<Dynamic>& b) {
  return (b - jac * x).norm() / b.norm();
}

class BoomerAmg : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!boomeramg_available()) {
      EXPECT_THROW(BoomerAmgPreconditioner{}, InvalidInput);
      GTEST_SKIP() << "nlobs was built without hypre";
    }
  }
};

// Multigrid's point: the iteration count of the preconditioned Krylov solve does not grow with n.
TEST_F(BoomerAmg, KeepsGmresIterationsFlatAsTheGridIsRefinedWhereIlu0sGrow) {
  std::vector<int> amg_iterations, ilu_iterations;
  for (const Index s : {16, 64, 128}) {
    const SparseJacobian jac = convection_diffusion(s, 0.0);
    const Vector<Dynamic> b = smooth_rhs(s * s);
    for (const std::string spec : {"gmres:preconditioner=boomeramg", "gmres:preconditioner=ilu0"}) {
      auto solver = make_linear_solver(spec);
      ASSERT_EQ(solver->setup(jac), LinearStatus::kSolved) << solver->message();
      Vector<Dynamic> x;
      ASSERT_EQ(solver->solve(b, x, 1e-10), LinearStatus::kSolved)
          << spec << ": " << solver->message();
      EXPECT_LE(relative_residual(jac, x, b), 1e-10) << spec;
      (spec.find("boomeramg") != std::string::npos ? amg_iterations : ilu_iterations)
          .push_back(solver->stats().iterations);
    }
  }
  // Measured: 9, 9, 9 iterations against ILU(0)'s 22, 83, 220 (restart 30).
  EXPECT_LE(amg_iterations.back(), 2 * amg_iterations.front());
  EXPECT_GE(ilu_iterations.back(), 4 * ilu_iterations.front());
  EXPECT_LT(amg_iterations.back(), ilu_iterations.back() / 4);
}

TEST_F(BoomerAmg, AgreesWithADirectSolveOnANonsymmetricOperatorAndReportsItsHierarchy) {
  const SparseJacobian jac = convection_diffusion(40, 20.0);
  const Vector<Dynamic> b = smooth_rhs(jac.rows());
  auto direct = make_linear_solver("klu");
  ASSERT_EQ(direct->setup(jac), LinearStatus::kSolved);
  Vector<Dynamic> expected;
  ASSERT_EQ(direct->solve(b, expected, 0.0), LinearStatus::kSolved);
  for (const int cycles : {1, 2}) {
    auto amg = std::make_unique<BoomerAmgPreconditioner>(BoomerAmgOptions{.cycles = cycles});
    BoomerAmgPreconditioner* handle = amg.get();
    GmresSolver gmres(GmresOptions{}, std::move(amg));
    ASSERT_EQ(gmres.setup(jac), LinearStatus::kSolved) << gmres.message();
    EXPECT_GT(handle->levels(), 1);
    Vector<Dynamic> x;
    ASSERT_EQ(gmres.solve(b, x, 1e-12), LinearStatus::kSolved) << gmres.message();
    EXPECT_LE((x - expected).lpNorm<Eigen::Infinity>(), 1e-9 * expected.lpNorm<Eigen::Infinity>());
    // Reusing the setup for a second right-hand side, as modified Newton does.
    const Vector<Dynamic> b2 = 2.0 * b;
    ASSERT_EQ(gmres.solve(b2, x, 1e-12), LinearStatus::kSolved);
    EXPECT_LE((x - 2.0 * expected).lpNorm<Eigen::Infinity>(),
              2e-9 * expected.lpNorm<Eigen::Infinity>());
  }
}

TEST_F(BoomerAmg, DrivesNewtonOnBratuToTheRootOfTheDirectSolver) {
  const Index s = 40;
  const Vector<Dynamic> x0 = Vector<Dynamic>::Zero(s * s);
  const RootProblem<> problem = sparse_autodiff_problem(test::bratu(s), x0);
  Vector<Dynamic> direct = x0, multigrid = x0;
  NewtonEngine<> klu(NewtonOptions{.line_search = true, .linear_solver = "klu"},
                     test::residual_stop());
  ASSERT_EQ(klu.solve(to_fixed_point(problem), direct).status, Status::kConverged);
  // The spec an engine takes (builtin_engines.hpp): linear=gmres,preconditioner=boomeramg.
  NewtonEngine<> amg(
      NewtonOptions{.line_search = true, .linear_solver = "gmres:preconditioner=boomeramg"},
      test::residual_stop());
  const Summary summary = amg.solve(to_fixed_point(problem), multigrid);
  ASSERT_EQ(summary.status, Status::kConverged) << summary.message;
  EXPECT_EQ(summary.linear_solver, "gmres");
  EXPECT_GT(summary.linear_iterations, 0);
  EXPECT_LE(summary.linear_iterations, 15 * summary.linear_setups);
  EXPECT_LE((multigrid - direct).lpNorm<Eigen::Infinity>(), 1e-8);
}

TEST_F(BoomerAmg, NamesANonFiniteOrNonSquareJacobianAndLeavesNothingToApply) {
  SparseJacobian jac = convection_diffusion(8, 0.0);
  BoomerAmgPreconditioner amg;
  ASSERT_EQ(amg.setup(jac), LinearStatus::kSolved) << amg.message();
  jac.coeffRef(17, 17) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(amg.setup(jac), LinearStatus::kNonFinite);
  EXPECT_NE(amg.message().find("row 17"), std::string::npos) << amg.message();
  // The good hierarchy before is gone with the failed setup: apply says so by NaN, which the
  // Krylov solvers name, rather than applying a stale M⁻¹.
  Vector<Dynamic> z;
  amg.apply(Vector<Dynamic>::Ones(64), z);
  ASSERT_EQ(z.size(), 64);
  EXPECT_TRUE(z.array().isNaN().all());
  EXPECT_EQ(amg.levels(), 0);

  SparseJacobian wide(4, 5);
  wide.insert(0, 0) = 1.0;
  EXPECT_EQ(amg.setup(wide), LinearStatus::kInvalidInput);
  EXPECT_NE(amg.message().find("not square"), std::string::npos) << amg.message();
  EXPECT_EQ(amg.setup(SparseJacobian(0, 0)), LinearStatus::kInvalidInput);
  EXPECT_NE(amg.message().find("empty"), std::string::npos) << amg.message();

  // A row without its diagonal entry, and an empty row: hypre would take another entry for the
  // diagonal (or mislabel the rows after an empty one), so both are refused, named.
  SparseJacobian no_diagonal = convection_diffusion(8, 0.0);
  no_diagonal.prune([](Index row, Index col, double) { return !(row == 9 && col == 9); });
  EXPECT_EQ(amg.setup(no_diagonal), LinearStatus::kSingular);
  EXPECT_NE(amg.message().find("J(9, 9) is not stored"), std::string::npos) << amg.message();
  SparseJacobian empty_row = convection_diffusion(8, 0.0);
  empty_row.prune([](Index row, Index, double) { return row != 40; });
  EXPECT_EQ(amg.setup(empty_row), LinearStatus::kSingular);
  EXPECT_NE(amg.message().find("J(40, 40)"), std::string::npos) << amg.message();

  BoomerAmgPreconditioner fresh;  // apply before any setup, then with r of the wrong size
  fresh.apply(Vector<Dynamic>::Ones(3), z);
  EXPECT_TRUE(z.array().isNaN().all());
  EXPECT_NE(fresh.message().find("before a successful setup"), std::string::npos);
  ASSERT_EQ(fresh.setup(convection_diffusion(8, 0.0)), LinearStatus::kSolved);
  fresh.apply(Vector<Dynamic>::Ones(63), z);
  ASSERT_EQ(z.size(), 63);
  EXPECT_TRUE(z.array().isNaN().all());
  EXPECT_NE(fresh.message().find("63 entries"), std::string::npos) << fresh.message();
}

TEST_F(BoomerAmg, TakesOneUnknownAndAJacobianNotYetCompressed) {
  SparseJacobian one(1, 1);
  one.insert(0, 0) = 4.0;
  auto solver = make_linear_solver("gmres:preconditioner=boomeramg");
  ASSERT_EQ(solver->setup(one), LinearStatus::kSolved) << solver->message();
  Vector<Dynamic> x;
  ASSERT_EQ(solver->solve(Vector<Dynamic>::Constant(1, 2.0), x, 1e-12), LinearStatus::kSolved);
  EXPECT_DOUBLE_EQ(x[0], 0.5);
  // Room reserved per column and filled out of order: Eigen keeps it uncompressed.
  SparseJacobian loose(3, 3);
  loose.reserve(Eigen::VectorXi::Constant(3, 4));
  loose.insert(2, 2) = 2.0;
  loose.insert(0, 1) = -1.0;
  loose.insert(0, 0) = 2.0;
  loose.insert(1, 1) = 2.0;
  ASSERT_FALSE(loose.isCompressed());
  ASSERT_EQ(solver->setup(loose), LinearStatus::kSolved) << solver->message();
  ASSERT_EQ(solver->solve(Vector<Dynamic>::Ones(3), x, 1e-12), LinearStatus::kSolved);
  EXPECT_NEAR(x[0], 0.75, 1e-12);
  EXPECT_NEAR(x[1], 0.5, 1e-12);
  EXPECT_NEAR(x[2], 0.5, 1e-12);
}

TEST_F(BoomerAmg, SolvesTheSameOperatorScaledBy1e300And1eMinus300) {
  // Hostile magnitudes: the hierarchy's strength test and relaxation are scale-free, so J·1e±300
  // must neither overflow to NaN nor underflow to a zero pivot.
  const SparseJacobian unit = convection_diffusion(20, 5.0);
  const Vector<Dynamic> b = smooth_rhs(unit.rows());
  for (const double scale : {1e300, 1e-300}) {
    const SparseJacobian jac = scale * unit;
    auto solver = make_linear_solver("gmres:preconditioner=boomeramg");
    ASSERT_EQ(solver->setup(jac), LinearStatus::kSolved) << scale << ": " << solver->message();
    Vector<Dynamic> x;
    ASSERT_EQ(solver->solve(b, x, 1e-10), LinearStatus::kSolved)
        << scale << ": " << solver->message();
    EXPECT_LE(relative_residual(jac, x, b), 1e-10) << scale;
  }
}

TEST_F(BoomerAmg, ASingularJacobianEndsTheKrylovSolveWithANamedFailure) {
  SparseJacobian jac = convection_diffusion(12, 0.0);
  for (SparseJacobian::InnerIterator it(jac, 30); it; ++it) it.valueRef() = 0.0;  // a zero row
  auto solver = make_linear_solver("gmres:preconditioner=boomeramg,max_iterations=60");
  const LinearStatus setup = solver->setup(jac);
  Vector<Dynamic> x;
  const LinearStatus status =
      setup == LinearStatus::kSolved ? solver->solve(smooth_rhs(144), x, 1e-10) : setup;
  // Row 30 of J x is 0 whatever x is, and b_30 ≠ 0: no solve can succeed. hypre's setup
  // refuses the zero diagonal entry; the Krylov solver passes its status and message on.
  EXPECT_EQ(status, LinearStatus::kSingular) << solver->message();
  EXPECT_NE(solver->message().find("HYPRE_BoomerAMGSetup"), std::string::npos) << solver->message();
}

TEST_F(BoomerAmg, TwoThreadsSolveAtOnceAndGetTheirOwnAnswers) {
  const SparseJacobian a = convection_diffusion(30, 0.0), b = convection_diffusion(30, 15.0);
  const Vector<Dynamic> rhs = smooth_rhs(900);
  Vector<Dynamic> xa, xb;
  LinearStatus sa = LinearStatus::kPackageFailure, sb = LinearStatus::kPackageFailure;
  const auto run = [&rhs](const SparseJacobian& jac, Vector<Dynamic>& x, LinearStatus& status) {
    auto solver = make_linear_solver("gmres:preconditioner=boomeramg");
    status = solver->setup(jac);
    for (int repeat = 0; repeat < 20 && status == LinearStatus::kSolved; ++repeat) {
      status = solver->solve(rhs, x, 1e-10);
    }
  };
  std::thread first(run, std::cref(a), std::ref(xa), std::ref(sa));
  std::thread second(run, std::cref(b), std::ref(xb), std::ref(sb));
  first.join();
  second.join();
  ASSERT_EQ(sa, LinearStatus::kSolved);
  ASSERT_EQ(sb, LinearStatus::kSolved);
  EXPECT_LE(relative_residual(a, xa, rhs), 1e-10);
  EXPECT_LE(relative_residual(b, xb, rhs), 1e-10);
}

TEST(BoomerAmgOptions, AreValidatedWhereTheyAreBuiltAndBelongToBoomeramgOnly) {
  for (const double bad : {0.0, 1.0, -0.5, std::numeric_limits<double>::quiet_NaN()}) {
    EXPECT_THROW(BoomerAmgOptions{.strong_threshold = bad}.validate(), InvalidInput) << bad;
    EXPECT_THROW(BoomerAmgPreconditioner(BoomerAmgOptions{.strong_threshold = bad}), InvalidInput);
  }
  for (const int bad : {0, -1, 101}) {
    EXPECT_THROW(BoomerAmgOptions{.cycles = bad}.validate(), InvalidInput) << bad;
  }
  EXPECT_NO_THROW((BoomerAmgOptions{.strong_threshold = 0.5, .cycles = 100}.validate()));
  for (const char* bad :
       {"gmres:preconditioner=boomeramg,strong_threshold=1.5",
        "gmres:preconditioner=boomeramg,cycles=0", "gmres:preconditioner=boomeramg,cycles=1e3",
        "gmres:preconditioner=ilu0,cycles=2", "bicgstab:strong_threshold=0.5",
        "gmres:preconditioner=boomeramg,drop_tolerance=1e-3"}) {
    EXPECT_THROW(make_linear_solver(bad), InvalidInput) << bad;
  }
  try {
    make_linear_solver("gmres:preconditioner=multigrid");
    ADD_FAILURE() << "an unknown preconditioner was accepted";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("boomeramg"), std::string::npos) << e.what();
  }
  if (boomeramg_available()) {
    EXPECT_NO_THROW(make_linear_solver("bicgstab:preconditioner=boomeramg,strong_threshold=0.5"));
  }
}

}  // namespace
}  // namespace nlobs
