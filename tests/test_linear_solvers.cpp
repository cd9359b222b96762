// The linear-solver layer (nlobs/solvers/linear/): every solver against dense LU on random
// well-conditioned sparse systems, band systems that need row interchanges, and a 2-D Bratu
// Jacobian (PETSc's SNES ex5, not shipped by nlobs); and each named failure: singular J,
// Krylov breakdown, the linear budget spent, a singular or NaN-returning preconditioner, bad
// sizes, NaN input, invalid options and specs.
#include <gtest/gtest.h>

#include <Eigen/QR>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "large_test_problems.hpp"
#include "nlobs/solvers/linear/band_lu.hpp"
#include "nlobs/solvers/linear/bicgstab.hpp"
#include "nlobs/solvers/linear/dense_lu.hpp"
#include "nlobs/solvers/linear/forcing_term.hpp"
#include "nlobs/solvers/linear/gmres.hpp"
#include "nlobs/solvers/linear/jacobian_product.hpp"
#include "nlobs/solvers/linear/klu.hpp"
#include "nlobs/solvers/linear/make_linear_solver.hpp"
#include "nlobs/solvers/linear/preconditioners.hpp"
#include "nlobs/solvers/linear/sparse_lu.hpp"
#include "nlobs/solvers/linear/umfpack.hpp"
#include "nlobs/solvers/sparse/compressed_jacobian.hpp"
#include "nlobs/solvers/sparse/sparsity_pattern.hpp"
#include "test_support.hpp"

namespace nlobs {
namespace {

using Triplets = std::vector<Eigen::Triplet<double>>;

SparseJacobian from_triplets(Index n, const Triplets& entries) {
  SparseJacobian jac(n, n);
  jac.setFromTriplets(entries.begin(), entries.end());
  jac.makeCompressed();
  return jac;
}

// 4 I + a random sparse part (about `per_row` entries in [−1, 1] per row): nonsymmetric, its
// eigenvalues within a disc around 4 that excludes 0 for per_row ≤ 3.
SparseJacobian random_sparse(Index n, int per_row, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  std::uniform_int_distribution<Index> column(0, n - 1);
  Triplets entries;
  for (Index i = 0; i < n; ++i) {
    entries.emplace_back(i, i, 4.0);
    for (int k = 0; k < per_row; ++k) entries.emplace_back(i, column(rng), value(rng));
  }
  return from_triplets(n, entries);
}

// A band matrix (lower, upper). With both widths positive its diagonal is small beside the
// other entries, so that LU needs row interchanges, which widen U's band; a triangular one gets
// a dominant diagonal instead (a small one would make it ill-conditioned as (1/diagonal)ⁿ).
SparseJacobian random_band(Index n, Index lower, Index upper, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  const double diagonal = lower > 0 && upper > 0 ? 0.1 : 2.0;
  Triplets entries;
  for (Index i = 0; i < n; ++i) {
    for (Index j = std::max<Index>(0, i - lower); j <= std::min(n - 1, i + upper); ++j) {
      entries.emplace_back(i, j, i == j ? 0.5 * diagonal * value(rng) + diagonal : value(rng));
    }
  }
  return from_triplets(n, entries);
}

// The Jacobian of 2-D Bratu, (4u − Σ neighbours)/h² − λ e^u, at u = 0.1 on an s×s grid.
SparseJacobian bratu_jacobian(Index s, double lambda = 6.0) {
  const double h2 = 1.0 / static_cast<double>((s + 1) * (s + 1));
  Triplets entries;
  for (Index r = 0; r < s; ++r) {
    for (Index c = 0; c < s; ++c) {
      const Index p = r * s + c;
      entries.emplace_back(p, p, 4.0 / h2 - lambda * std::exp(0.1));
      if (r > 0) entries.emplace_back(p, p - s, -1.0 / h2);
      if (r + 1 < s) entries.emplace_back(p, p + s, -1.0 / h2);
      if (c > 0) entries.emplace_back(p, p - 1, -1.0 / h2);
      if (c + 1 < s) entries.emplace_back(p, p + 1, -1.0 / h2);
    }
  }
  return from_triplets(s * s, entries);
}

Vector<Dynamic> random_vector(Index n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  Vector<Dynamic> v(n);
  for (Index i = 0; i < n; ++i) v[i] = value(rng);
  return v;
}

Vector<Dynamic> dense_solution(const SparseJacobian& jac, const Vector<Dynamic>& b) {
  return Matrix<Dynamic, Dynamic>(jac).partialPivLu().solve(b);
}

const std::vector<std::string> kEverySolver = {"dense-lu",
                                               "band-lu",
                                               "sparse-lu",
                                               "klu",
                                               "umfpack",
                                               "umfpack:ordering=metis",
                                               "gmres",
                                               "gmres:preconditioner=jacobi",
                                               "gmres:preconditioner=ilu0",
                                               "gmres:preconditioner=ilut,restart=5",
                                               "bicgstab",
                                               "bicgstab:preconditioner=ilu0",
                                               "bicgstab:preconditioner=ilut,drop_tolerance=1e-3"};

class EverySolver : public ::testing::TestWithParam<std::string> {};

TEST_P(EverySolver, AgreesWithDenseLuOnRandomSparseSystems) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const SparseJacobian jac = random_sparse(80, 3, seed);
    const Vector<Dynamic> b = random_vector(80, seed + 10);
    const Vector<Dynamic> expected = dense_solution(jac, b);
    std::unique_ptr<LinearSolver> solver = make_linear_solver(GetParam());
    ASSERT_EQ(solver->setup(jac), LinearStatus::kSolved) << solver->message();
    Vector<Dynamic> x;
    ASSERT_EQ(solver->solve(b, x, 1e-12), LinearStatus::kSolved) << solver->message();
    EXPECT_LE((jac * x - b).norm(), 1e-10 * b.norm()) << GetParam() << " seed " << seed;
    EXPECT_LE((x - expected).norm(), 1e-9 * expected.norm()) << GetParam() << " seed " << seed;
    Vector<Dynamic> in_place = b;  // x and b one vector
    ASSERT_EQ(solver->solve(in_place, in_place, 1e-12), LinearStatus::kSolved);
    EXPECT_LE((in_place - x).norm(), 1e-10 * x.norm()) << GetParam() << " in place";
    EXPECT_EQ(solver->stats().setups, 1);
    EXPECT_EQ(solver->stats().solves, 2);
    EXPECT_EQ(solver->stats().failures, 0);
    EXPECT_EQ(solver->stats().iterations > 0, solver->iterative());
  }
}

TEST_P(EverySolver, SolvesTheBratuJacobianAndReusesItsSetup) {
  const SparseJacobian jac = bratu_jacobian(30);  // n = 900
  std::unique_ptr<LinearSolver> solver = make_linear_solver(GetParam());
  ASSERT_EQ(solver->setup(jac), LinearStatus::kSolved) << solver->message();
  for (unsigned seed : {4u, 5u}) {  // two right-hand sides, one setup
    const Vector<Dynamic> b = random_vector(jac.rows(), seed);
    Vector<Dynamic> x;
    ASSERT_EQ(solver->solve(b, x, 1e-10), LinearStatus::kSolved) << solver->message();
    EXPECT_LE((jac * x - b).norm(), 1e-9 * b.norm()) << GetParam();
    if (solver->iterative()) {
      EXPECT_LE(solver->stats().last_residual, 1e-10);
      EXPECT_NEAR(solver->stats().last_residual, (jac * x - b).norm() / b.norm(), 1e-12);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(LinearSolvers, EverySolver, ::testing::ValuesIn(kEverySolver),
                         [](const auto& param_info) {
                           std::string name = param_info.param;
                           for (char& c : name) {
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           }
                           return name;
                         });

TEST(BandLuSolver, PivotsAcrossTheBandAndMatchesDenseLu) {
  for (const auto& [lower, upper] :
       std::vector<std::pair<Index, Index>>{{0, 0}, {1, 1}, {2, 3}, {4, 0}, {0, 4}}) {
    const SparseJacobian jac =
        random_band(60, lower, upper, static_cast<unsigned>(lower * 7 + upper));
    const Vector<Dynamic> b = random_vector(60, 9);
    for (BandLuSolver solver : {BandLuSolver(), BandLuSolver(lower, upper), BandLuSolver(6, 6)}) {
      ASSERT_EQ(solver.setup(jac), LinearStatus::kSolved)
          << solver.message() << " (lower " << lower << ", upper " << upper << ")";
      Vector<Dynamic> x;
      ASSERT_EQ(solver.solve(b, x, 0.0), LinearStatus::kSolved);
      const Vector<Dynamic> expected = dense_solution(jac, b);
      EXPECT_LE((x - expected).norm(), 1e-10 * expected.norm()) << lower << "," << upper;
    }
    BandLuSolver found;
    ASSERT_EQ(found.setup(jac), LinearStatus::kSolved);
    EXPECT_EQ(found.lower(), lower);
    EXPECT_EQ(found.upper(), upper);
  }
}

TEST(BandLuSolver, RefusesAnEntryOutsideItsDeclaredBandAndNegativeWidths) {
  const SparseJacobian jac = random_band(20, 2, 1, 3);
  BandLuSolver narrow(1, 1);
  EXPECT_EQ(narrow.setup(jac), LinearStatus::kInvalidInput);
  EXPECT_NE(narrow.message().find("outside the declared band"), std::string::npos)
      << narrow.message();
  EXPECT_THROW(BandLuSolver(-1, 2), InvalidInput);
  EXPECT_THROW(make_linear_solver("band-lu:lower=1"), InvalidInput);
  EXPECT_THROW(make_linear_solver("band-lu:lower=-1,upper=1"), InvalidInput);
}

TEST(KluSolver, RefactorsWithTheLastPivotOrderAndFactorsAfreshWhenItGoesBad) {
  KluSolver solver;
  SparseJacobian jac = random_sparse(50, 3, 7);
  ASSERT_EQ(solver.setup(jac), LinearStatus::kSolved);
  jac.coeffs() *= 1.5;  // same pattern, new values
  ASSERT_EQ(solver.setup(jac), LinearStatus::kSolved);
  EXPECT_EQ(solver.refactorizations(), 1);
  const Vector<Dynamic> b = random_vector(50, 8);
  Vector<Dynamic> x;
  ASSERT_EQ(solver.solve(b, x, 0.0), LinearStatus::kSolved);
  EXPECT_LE((x - dense_solution(jac, b)).norm(), 1e-10 * x.norm());

  // [[1, 1], [1, 0]] is factored without interchange; [[0, 1], [1, 1]] has the same pattern
  // but a zero where the old order pivots: the refactorisation fails, a fresh factor succeeds.
  KluSolver two;
  SparseJacobian first = from_triplets(2, {{0, 0, 1.0}, {0, 1, 1.0}, {1, 0, 1.0}, {1, 1, 1e-300}});
  ASSERT_EQ(two.setup(first), LinearStatus::kSolved) << two.message();
  SparseJacobian second = first;
  second.coeffRef(0, 0) = 0.0;
  second.coeffRef(1, 1) = 1.0;
  ASSERT_EQ(two.setup(second), LinearStatus::kSolved) << two.message();
  EXPECT_EQ(two.refactorizations(), 0);
  Vector<Dynamic> b2(2);
  b2 << 1.0, 3.0;
  ASSERT_EQ(two.solve(b2, x, 0.0), LinearStatus::kSolved);
  EXPECT_NEAR(x[0], 2.0, 1e-14);
  EXPECT_NEAR(x[1], 1.0, 1e-14);
}

// A 5-point operator with unsymmetric, solution-dependent values, as a 2-D Newton step gives:
// UMFPACK keeps its analysis across values of one pattern, takes a new pattern afresh, and
// agrees with dense LU (and so with KLU) each time.
TEST(UmfpackSolver, KeepsItsAnalysisForOnePatternAndAgreesWithDenseLu) {
  const Index s = 30, n = s * s;
  const auto grid = [&](double shift, bool extra) {
    std::vector<Eigen::Triplet<double, int>> t;
    for (Index r = 0; r < s; ++r) {
      for (Index c = 0; c < s; ++c) {
        const int p = static_cast<int>(r * s + c);
        t.emplace_back(p, p, 4.0 + shift + 0.01 * static_cast<double>(p % 7));
        if (r > 0) t.emplace_back(p, p - static_cast<int>(s), -1.0 - shift);
        if (r + 1 < s) t.emplace_back(p, p + static_cast<int>(s), -0.9);
        if (c > 0) t.emplace_back(p, p - 1, -1.2);
        if (c + 1 < s) t.emplace_back(p, p + 1, -0.8 + shift);
        if (extra && p + 2 * static_cast<int>(s) < static_cast<int>(n)) {
          t.emplace_back(p, p + 2 * static_cast<int>(s), 0.3);
        }
      }
    }
    SparseJacobian jac(n, n);
    jac.setFromTriplets(t.begin(), t.end());
    jac.makeCompressed();
    return jac;
  };
  const Vector<Dynamic> b = random_vector(n, 5);
  for (const char* spec : {"umfpack", "umfpack:ordering=metis"}) {
    std::unique_ptr<LinearSolver> solver = make_linear_solver(spec);
    const auto* umfpack = dynamic_cast<const UmfpackSolver*>(solver.get());
    ASSERT_NE(umfpack, nullptr);
    int analyses = 0;
    for (const auto& [shift, extra] : {std::pair{0.0, false}, {0.5, false}, {0.5, true}}) {
      const SparseJacobian jac = grid(shift, extra);
      ASSERT_EQ(solver->setup(jac), LinearStatus::kSolved) << spec << ": " << solver->message();
      analyses += shift == 0.0 || extra;  // a first pattern, then a new one
      EXPECT_EQ(umfpack->symbolic_analyses(), analyses) << spec << " shift " << shift;
      Vector<Dynamic> x;
      ASSERT_EQ(solver->solve(b, x, 0.0), LinearStatus::kSolved) << solver->message();
      const Vector<Dynamic> expected = dense_solution(jac, b);
      EXPECT_LE((x - expected).norm(), 1e-10 * expected.norm()) << spec << " shift " << shift;
    }
    EXPECT_EQ(solver->stats().setups, 3);
    EXPECT_EQ(solver->stats().failures, 0);
  }
}

// auto's choice by pattern and size: a narrow band is band-lu at any size; a wide one (the
// 5-point stencil's width is the grid's side) is klu below kAutoMultifrontalSize and umfpack
// from there; a named solver is kept.
TEST(ChooseLinearSolver, TakesUmfpackForWideBandsFromTwentyThousandUnknowns) {
  const auto five_point = [](Index s) {
    std::vector<std::pair<Index, Index>> e;
    for (Index p = 0; p < s * s; ++p) {
      e.emplace_back(p, p);
      if (p >= s) e.emplace_back(p, p - s);
      if (p + s < s * s) e.emplace_back(p, p + s);
    }
    return SparsityPattern::from_entries(s * s, s * s, e);
  };
  EXPECT_EQ(choose_linear_solver("auto", SparsityPattern::band(100000, 1, 1), 100000), "band-lu");
  EXPECT_EQ(choose_linear_solver("auto", five_point(100), 10000), "klu");
  EXPECT_EQ(choose_linear_solver("auto", five_point(141), 141 * 141), "klu");      // 19 881
  EXPECT_EQ(choose_linear_solver("auto", five_point(142), 142 * 142), "umfpack");  // 20 164
  EXPECT_EQ(choose_linear_solver("klu", five_point(142), 142 * 142), "klu");
  static_assert(141 * 141 < kAutoMultifrontalSize && 142 * 142 >= kAutoMultifrontalSize);
}

TEST(DirectSolvers, ReportASingularJacobianWithTheirMessage) {
  // Row 2 is zero: structurally singular.
  Triplets entries;
  for (Index i = 0; i < 6; ++i) {
    if (i != 2) entries.emplace_back(i, i, 2.0);
    if (i + 1 < 6 && i != 2) entries.emplace_back(i, i + 1, 1.0);
  }
  const SparseJacobian zero_row = from_triplets(6, entries);
  // Row 1 = row 0 / 3, rounded: elimination leaves a pivot of rounding size (numerically
  // singular, though perhaps not exactly).
  const double third = 1.0 / 3.0;
  const SparseJacobian equal_rows = from_triplets(3, {{0, 0, 0.1},
                                                      {0, 1, 0.7},
                                                      {1, 0, 0.1 * third},
                                                      {1, 1, 0.7 * third},
                                                      {2, 2, 3.0},
                                                      {1, 2, 0.0}});
  for (const std::string name : {"dense-lu", "band-lu", "sparse-lu", "klu", "umfpack"}) {
    for (const SparseJacobian* jac : {&zero_row, &equal_rows}) {
      std::unique_ptr<LinearSolver> solver = make_linear_solver(name);
      EXPECT_EQ(solver->setup(*jac), LinearStatus::kSingular) << name << ": " << solver->message();
      EXPECT_NE(solver->message().find("singular"), std::string::npos) << solver->message();
      EXPECT_EQ(solver->stats().failures, 1);
      Vector<Dynamic> x;
      EXPECT_EQ(solver->solve(Vector<Dynamic>::Ones(jac->rows()), x, 0.5),
                LinearStatus::kInvalidInput)
          << name << ": a failed setup leaves nothing to solve with";
    }
  }
}

TEST(DirectSolvers, JudgeSingularityAfterEquilibratingRows) {
  // Rows scaled by 10^±15: regular, however unequal; every direct solver must agree with dense
  // LU of the same system (a pivot test against max |J_ij| would call it singular).
  SparseJacobian jac = random_sparse(40, 3, 21);
  for (Index i = 0; i < jac.rows(); ++i) jac.row(i) *= std::pow(10.0, i % 2 == 0 ? 15.0 : -15.0);
  const Vector<Dynamic> b = random_vector(40, 22);
  const Vector<Dynamic> expected = dense_solution(jac, b);
  for (const std::string name : {"dense-lu", "band-lu", "sparse-lu", "klu", "umfpack"}) {
    std::unique_ptr<LinearSolver> solver = make_linear_solver(name);
    ASSERT_EQ(solver->setup(jac), LinearStatus::kSolved) << name << ": " << solver->message();
    Vector<Dynamic> x;
    ASSERT_EQ(solver->solve(b, x, 0.0), LinearStatus::kSolved);
    EXPECT_LE((x - expected).norm(), 1e-9 * expected.norm()) << name;
  }
}

TEST(DirectSolvers, RefuseToSolveAfterAFailedSetupThatFollowedAGoodOne) {
  const SparseJacobian good = random_sparse(8, 2, 4);
  SparseJacobian bad = good;
  bad.row(5) *= 0.0;
  for (const auto& [name, description] : linear_solver_names()) {
    std::unique_ptr<LinearSolver> solver = make_linear_solver(name);
    ASSERT_EQ(solver->setup(good), LinearStatus::kSolved) << name;
    const LinearStatus status = solver->setup(bad);
    Vector<Dynamic> x;
    if (solver->iterative()) {
      // A Krylov solver sets up with a singular J (no preconditioner to build) and names the
      // failure at solve time.
      EXPECT_EQ(status, LinearStatus::kSolved) << name;
      EXPECT_NE(solver->solve(Vector<Dynamic>::Ones(8), x, 1e-10), LinearStatus::kSolved) << name;
    } else {
      EXPECT_EQ(status, LinearStatus::kSingular) << name;
      EXPECT_EQ(solver->solve(Vector<Dynamic>::Ones(8), x, 0.5), LinearStatus::kInvalidInput)
          << name << ": the old factor must not be used for the new J";
    }
  }
}

TEST(GmresSolver, KeepsAtMostNVectorsAndNamesARoundingLevelBreakdown) {
  const SparseJacobian small = random_sparse(5, 2, 31);
  GmresSolver wide(GmresOptions{.restart = 1000});
  ASSERT_EQ(wide.setup(small), LinearStatus::kSolved);
  Vector<Dynamic> x;
  ASSERT_EQ(wide.solve(random_vector(5, 3), x, 1e-12), LinearStatus::kSolved) << wide.message();
  EXPECT_LE(wide.stats().iterations, 6);

  // J = Q diag(1, 2, 3, 4, 5, 0) Qᵀ: singular to rounding, b partly along its null vector q₆.
  Matrix<Dynamic, Dynamic> random(6, 6);
  for (Index j = 0; j < 6; ++j) random.col(j) = random_vector(6, 40u + static_cast<unsigned>(j));
  const Matrix<Dynamic, Dynamic> q =
      Eigen::HouseholderQR<Matrix<Dynamic, Dynamic>>(random).householderQ();
  Vector<Dynamic> d(6);
  d << 1.0, 2.0, 3.0, 4.0, 5.0, 0.0;
  const Matrix<Dynamic, Dynamic> dense = q * d.asDiagonal() * q.transpose();
  const SparseJacobian singular = dense.sparseView();
  GmresSolver gmres;
  ASSERT_EQ(gmres.setup(singular), LinearStatus::kSolved);
  const Vector<Dynamic> b = q.col(0) + 0.5 * q.col(5);
  EXPECT_EQ(gmres.solve(b, x, 1e-10), LinearStatus::kBreakdown) << gmres.message();
  EXPECT_LE(gmres.stats().iterations, 7) << "named at once, not after the whole budget";
  EXPECT_GT(gmres.stats().last_residual, 0.1);
  // Consistent (b in J's range): solved.
  ASSERT_EQ(gmres.solve(q.col(0) + q.col(3), x, 1e-10), LinearStatus::kSolved) << gmres.message();
  EXPECT_LE((dense * x - q.col(0) - q.col(3)).norm(), 1e-9);
}

TEST(EverySolverInput, RefusesBadSizesNonFiniteValuesAndSolveBeforeSetup) {
  for (const auto& [name, description] : linear_solver_names()) {
    std::unique_ptr<LinearSolver> solver = make_linear_solver(name);
    Vector<Dynamic> x;
    EXPECT_EQ(solver->solve(Vector<Dynamic>::Ones(3), x, 0.5), LinearStatus::kInvalidInput) << name;
    EXPECT_NE(solver->message().find("before a successful setup"), std::string::npos);
    SparseJacobian rectangular(3, 2);
    EXPECT_EQ(solver->setup(rectangular), LinearStatus::kInvalidInput) << name;
    SparseJacobian jac = random_sparse(10, 2, 11);
    jac.coeffRef(4, 4) = std::numeric_limits<double>::quiet_NaN();
    EXPECT_EQ(solver->setup(jac), LinearStatus::kNonFinite) << name;
    EXPECT_NE(solver->message().find("row 4"), std::string::npos) << solver->message();
    jac.coeffRef(4, 4) = 4.0;
    ASSERT_EQ(solver->setup(jac), LinearStatus::kSolved) << name;
    EXPECT_EQ(solver->solve(Vector<Dynamic>::Ones(9), x, 0.5), LinearStatus::kInvalidInput);
    Vector<Dynamic> b = Vector<Dynamic>::Ones(10);
    b[3] = std::numeric_limits<double>::infinity();
    EXPECT_EQ(solver->solve(b, x, 0.5), LinearStatus::kNonFinite) << name;
    if (solver->iterative()) {
      for (double bad : {0.0, 1.0, -1e-3, std::numeric_limits<double>::quiet_NaN()}) {
        EXPECT_EQ(solver->solve(Vector<Dynamic>::Ones(10), x, bad), LinearStatus::kInvalidInput)
            << name << " tolerance " << bad;
      }
    }
    EXPECT_EQ(solver->solve(Vector<Dynamic>::Zero(10), x, 0.5), LinearStatus::kSolved) << name;
    EXPECT_EQ(x, Vector<Dynamic>::Zero(10));
  }
}

TEST(KrylovSolvers, NameABreakdown) {
  // GMRES: J e₁ = 0, so the Krylov space of b = e₁ holds no better x.
  GmresSolver gmres;
  ASSERT_EQ(gmres.setup(from_triplets(2, {{0, 1, 1.0}})), LinearStatus::kSolved);
  Vector<Dynamic> b(2), x;
  b << 1.0, 0.0;
  EXPECT_EQ(gmres.solve(b, x, 1e-8), LinearStatus::kBreakdown);
  EXPECT_NE(gmres.message().find("breakdown"), std::string::npos) << gmres.message();
  // BiCGSTAB on the swap matrix from b = e₁: (r₀, J p) = 0 at once, though J is regular.
  BicgstabSolver bicgstab;
  ASSERT_EQ(bicgstab.setup(from_triplets(2, {{0, 1, 1.0}, {1, 0, 1.0}})), LinearStatus::kSolved);
  EXPECT_EQ(bicgstab.solve(b, x, 1e-8), LinearStatus::kBreakdown);
  EXPECT_NE(bicgstab.message().find("(r0, J p) vanished"), std::string::npos) << bicgstab.message();
  // GMRES solves it: the breakdown is BiCGSTAB's, not the system's.
  ASSERT_EQ(gmres.setup(from_triplets(2, {{0, 1, 1.0}, {1, 0, 1.0}})), LinearStatus::kSolved);
  EXPECT_EQ(gmres.solve(b, x, 1e-8), LinearStatus::kSolved) << gmres.message();
  EXPECT_NEAR(x[1], 1.0, 1e-15);
}

TEST(KrylovSolvers, NameALinearBudgetSpent) {
  // The 1-D Laplacian at n = 400 needs far more than 10 unpreconditioned iterations.
  Triplets entries;
  for (Index i = 0; i < 400; ++i) {
    entries.emplace_back(i, i, 2.0);
    if (i > 0) entries.emplace_back(i, i - 1, -1.0);
    if (i + 1 < 400) entries.emplace_back(i, i + 1, -1.0);
  }
  const SparseJacobian jac = from_triplets(400, entries);
  for (const std::string spec : {"gmres:max_iterations=10", "gmres:restart=3,max_iterations=10",
                                 "bicgstab:max_iterations=10"}) {
    std::unique_ptr<LinearSolver> solver = make_linear_solver(spec);
    ASSERT_EQ(solver->setup(jac), LinearStatus::kSolved);
    Vector<Dynamic> x;
    EXPECT_EQ(solver->solve(random_vector(400, 1), x, 1e-10), LinearStatus::kNotConverged) << spec;
    EXPECT_NE(solver->message().find("no convergence in 10 iterations"), std::string::npos)
        << solver->message();
    EXPECT_EQ(solver->stats().iterations, 10) << spec;
    EXPECT_GT(solver->stats().last_residual, 1e-10);
    EXPECT_TRUE(x.allFinite()) << "the best iterate is still returned";
  }
}

TEST(KrylovSolvers, NameASingularOrNonFinitePreconditioner) {
  SparseJacobian jac = random_sparse(12, 2, 5);
  jac.coeffRef(7, 7) = 0.0;
  GmresSolver jacobi({}, std::make_unique<JacobiPreconditioner>());
  EXPECT_EQ(jacobi.setup(jac), LinearStatus::kSingular);
  EXPECT_NE(jacobi.message().find("J(7, 7) = 0"), std::string::npos) << jacobi.message();

  // ILU(0) needs every diagonal entry in the pattern.
  Triplets no_diagonal = {{0, 0, 1.0}, {0, 1, 1.0}, {1, 0, 1.0}};
  BicgstabSolver ilu0({}, std::make_unique<Ilu0Preconditioner>());
  EXPECT_EQ(ilu0.setup(from_triplets(2, no_diagonal)), LinearStatus::kSingular);
  EXPECT_NE(ilu0.message().find("row 1"), std::string::npos) << ilu0.message();

  // A user's preconditioner that returns NaN on its third application.
  int calls = 0;
  auto nan_later = [&calls](const Vector<Dynamic>& r, Vector<Dynamic>& z) {
    z = r;
    if (++calls == 3) z[0] = std::numeric_limits<double>::quiet_NaN();
  };
  for (int which = 0; which < 2; ++which) {
    calls = 0;
    std::unique_ptr<KrylovSolver> solver;
    auto user = std::make_unique<CallablePreconditioner>(nan_later);
    if (which == 0) {
      solver = std::make_unique<GmresSolver>(GmresOptions{}, std::move(user));
    } else {
      solver = std::make_unique<BicgstabSolver>(BicgstabOptions{}, std::move(user));
    }
    ASSERT_EQ(solver->setup(random_sparse(30, 3, 6)), LinearStatus::kSolved);
    Vector<Dynamic> x;
    EXPECT_EQ(solver->solve(random_vector(30, 2), x, 1e-12), LinearStatus::kNonFinite);
    EXPECT_NE(solver->message().find("preconditioner user returned a non-finite value"),
              std::string::npos)
        << solver->message();
  }
  EXPECT_THROW(CallablePreconditioner({}), InvalidInput);
}

TEST(KrylovSolvers, SolveJacobianFreeWithAnApproximationForThePreconditioner) {
  const SparseJacobian jac = bratu_jacobian(20);
  const Vector<Dynamic> b = random_vector(jac.rows(), 3);
  int products = 0;
  auto product = [&](const Vector<Dynamic>& v, Vector<Dynamic>& jv) {
    ++products;
    jv = jac * v;
  };
  GmresSolver plain;
  ASSERT_EQ(plain.setup(product, jac.rows()), LinearStatus::kSolved);
  Vector<Dynamic> x;
  ASSERT_EQ(plain.solve(b, x, 1e-10), LinearStatus::kSolved) << plain.message();
  EXPECT_LE((jac * x - b).norm(), 1e-9 * b.norm());
  // One product per Arnoldi step, one per restart cycle for the true residual (restart 30).
  const int iterations = plain.stats().iterations;
  EXPECT_EQ(products, iterations + (iterations + 29) / 30);

  GmresSolver preconditioned({}, std::make_unique<Ilu0Preconditioner>());
  EXPECT_EQ(preconditioned.setup(product, jac.rows()), LinearStatus::kInvalidInput)
      << "a preconditioner needs a matrix";
  ASSERT_EQ(preconditioned.setup(product, jac.rows(), &jac), LinearStatus::kSolved);
  ASSERT_EQ(preconditioned.solve(b, x, 1e-10), LinearStatus::kSolved);
  EXPECT_LT(preconditioned.stats().iterations, plain.stats().iterations);

  // An operator that returns the wrong size or NaN is named.
  GmresSolver bad;
  ASSERT_EQ(bad.setup([](const Vector<Dynamic>& v, Vector<Dynamic>& jv) { jv = 2.0 * v.head(3); },
                      jac.rows()),
            LinearStatus::kSolved);
  EXPECT_EQ(bad.solve(b, x, 1e-8), LinearStatus::kNonFinite);
  EXPECT_NE(bad.message().find("J v has size 3"), std::string::npos) << bad.message();
  EXPECT_EQ(bad.setup(KrylovSolver::Operator{}, 4), LinearStatus::kInvalidInput);
}

TEST(JacobianProducts, MatchTheAssembledJacobianAndDriveAJacobianFreeGmres) {
  const Index s = 15;
  auto f = test::bratu(s);
  Vector<Dynamic> u(s * s);
  for (Index i = 0; i < u.size(); ++i) u[i] = 0.3 * std::sin(0.1 * static_cast<double>(i));
  CompressedJacobian compressed(detect_sparsity(f, u, s * s));
  SparseJacobian jac;
  compressed.autodiff(f, u, jac);
  Vector<Dynamic> fu;
  f(u, fu);

  AutodiffJacobianProduct exact(f);
  exact.at(u);
  DifferenceJacobianProduct difference(f);
  difference.at(u, fu);
  Vector<Dynamic> jv, dv;
  for (unsigned seed : {1u, 2u}) {
    const Vector<Dynamic> v = random_vector(u.size(), seed);
    exact(v, jv);
    EXPECT_LE((jv - jac * v).norm(), 1e-12 * (jac * v).norm());
    difference(v, dv);
    EXPECT_LE((dv - jac * v).norm(), 1e-6 * (jac * v).norm());
    EXPECT_GT((dv - jac * v).norm(), 0.0) << "a difference quotient is not exact";
  }
  EXPECT_EQ(difference.evaluations(), 2);
  difference(Vector<Dynamic>::Zero(u.size()), dv);
  EXPECT_EQ(dv, Vector<Dynamic>::Zero(u.size())) << "J 0 = 0 without evaluating F at x + inf";
  EXPECT_THROW(exact(Vector<Dynamic>::Ones(3), jv), InvalidInput);

  // Jacobian-free GMRES (the preconditioner from the assembled J) = KLU on J.
  GmresSolver gmres({}, std::make_unique<Ilu0Preconditioner>());
  ASSERT_EQ(gmres.setup(std::ref(exact), u.size(), &jac), LinearStatus::kSolved);
  Vector<Dynamic> x, expected;
  ASSERT_EQ(gmres.solve(fu, x, 1e-11), LinearStatus::kSolved) << gmres.message();
  KluSolver klu;
  ASSERT_EQ(klu.setup(jac), LinearStatus::kSolved);
  ASSERT_EQ(klu.solve(fu, expected, 0.0), LinearStatus::kSolved);
  EXPECT_LE((x - expected).norm(), 1e-9 * expected.norm());
}

TEST(ForcingTerm, FollowsEisenstatWalkerWithItsSafeguardsAndBounds) {
  using Choice = ForcingTermOptions::Choice;
  ForcingTerm one;  // choice 1, η_0 = 0.1, η_max = 0.9
  EXPECT_DOUBLE_EQ(one.eta(), 0.1);
  // |0.5 − 0.4| / 1 = 0.1; the safeguard 0.1^φ ≈ 0.024 is below 0.1 and does not apply.
  one.update(0.5, 1.0, 0.4);
  EXPECT_NEAR(one.eta(), 0.1, 1e-15);
  // |1.0 − 0.1| / 1 = 0.9 = η_max.
  one.update(1.0, 1.0, 0.1);
  EXPECT_DOUBLE_EQ(one.eta(), 0.9);
  // Raw 0.01, but η_{k−1}^φ = 0.9^1.618… ≈ 0.843 > 0.1: the safeguard keeps η from collapsing.
  one.update(0.51, 1.0, 0.5);
  EXPECT_NEAR(one.eta(), std::pow(0.9, (1.0 + std::sqrt(5.0)) / 2.0), 1e-12);
  one.restart();
  EXPECT_DOUBLE_EQ(one.eta(), 0.1);
  one.update(1e-30, 1.0, 1e-30);  // raw 0: floored at η_min
  EXPECT_DOUBLE_EQ(one.eta(), 1e-10);
  one.update(std::nan(""), 1.0, 0.5);
  EXPECT_DOUBLE_EQ(one.eta(), 0.9) << "a non-finite η is the loosest, not NaN";

  ForcingTerm two(ForcingTermOptions{.choice = Choice::kEisenstatWalker2});
  two.update(0.5, 1.0, 0.0);  // 0.9 · 0.5² = 0.225; safeguard 0.9 · 0.1² = 0.009
  EXPECT_NEAR(two.eta(), 0.225, 1e-15);
  two.update(0.01, 1.0, 0.0);  // raw 9e-5; safeguard 0.9 · 0.225² ≈ 0.0456 < 0.1: raw
  EXPECT_NEAR(two.eta(), 9e-5, 1e-15);

  ForcingTerm constant(ForcingTermOptions{.choice = Choice::kConstant, .initial = 0.05});
  constant.update(0.5, 1.0, 0.4);
  EXPECT_DOUBLE_EQ(constant.eta(), 0.05);

  EXPECT_THROW(ForcingTerm(ForcingTermOptions{.initial = 1.0}), InvalidInput);
  EXPECT_THROW(ForcingTerm(ForcingTermOptions{.maximum = 0.0}), InvalidInput);
  EXPECT_THROW(ForcingTerm(ForcingTermOptions{.minimum = 0.95}), InvalidInput);
  EXPECT_THROW(ForcingTerm(ForcingTermOptions{.gamma = 1.5}), InvalidInput);
  EXPECT_THROW(ForcingTerm(ForcingTermOptions{.alpha = 1.0}), InvalidInput);
}

TEST(LinearSolverOptions, AreValidatedWhereTheyAreBuilt) {
  EXPECT_THROW(GmresSolver(GmresOptions{.restart = 0}), InvalidInput);
  EXPECT_THROW(GmresSolver(GmresOptions{.max_iterations = 0}), InvalidInput);
  EXPECT_THROW(BicgstabSolver(BicgstabOptions{.max_iterations = -3}), InvalidInput);
  EXPECT_THROW(IlutPreconditioner(IlutOptions{.drop_tolerance = 0.0}), InvalidInput);
  EXPECT_THROW(IlutPreconditioner(IlutOptions{.drop_tolerance = std::nan("")}), InvalidInput);
  EXPECT_THROW(IlutPreconditioner(IlutOptions{.fill_factor = 0}), InvalidInput);
  EXPECT_EQ(test::message_of([] { make_linear_solver("cholesky"); }),
            "linear solver 'cholesky' is unknown; valid: dense-lu, band-lu, sparse-lu, klu, "
            "umfpack, gmres, bicgstab");
  EXPECT_EQ(test::message_of([] { make_linear_solver("umfpack:ordering=colamd"); }),
            "linear solver umfpack: ordering 'colamd' is unknown; valid: amd, metis");
  EXPECT_THROW(make_linear_solver("umfpack:drop_tolerance=0.1"), InvalidInput);
  EXPECT_THROW(make_linear_solver("gmres:restart=0"), InvalidInput);
  EXPECT_THROW(make_linear_solver("gmres:preconditioner=amg"), InvalidInput);
  EXPECT_THROW(make_linear_solver("gmres:tolerance=1e-3"), InvalidInput);
  EXPECT_THROW(make_linear_solver("klu:ordering=amd"), InvalidInput);
  EXPECT_THROW(make_linear_solver("bicgstab:preconditioner=jacobi,fill_factor=3"), InvalidInput);
  const std::unique_ptr<LinearSolver> solver = make_linear_solver("gmres:restart=7");
  const auto* gmres = dynamic_cast<const GmresSolver*>(solver.get());
  ASSERT_NE(gmres, nullptr);
  EXPECT_EQ(gmres->options().restart, 7);
}

}  // namespace
}  // namespace nlobs
