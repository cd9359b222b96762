// PETSc SNES as a reference solver (reference/src/petsc_solver.cpp): on systems nlobs does not
// ship (a cubic chain with a declared tridiagonal pattern, a 2×2 circle-and-line without one),
// with PETSc's options passed through and shown to reach it, the names parsed and refused, the
// budget, NaN, a throwing F and malformed patterns; and in the suite beside our engines. Every
// test runs with a PETSC_OPTIONS that would break them if it reached the solvers.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "invalid_argument_message.hpp"
#include "nlobs/reference/petsc_solver.hpp"
#include "nlobs/reference/problem_suite.hpp"
#include "nlobs/registry/problem_sets.hpp"

namespace nlobs {
namespace {

// Set before any test starts PETSc (a static's initialisation): one Newton iteration, a basic
// line search and one colour per column, were PETSc's global options to reach our solvers or
// the colouring PETSc makes during a solve.
const bool kHostileEnvironment =
    setenv("PETSC_OPTIONS",
           "-snes_max_it 1 -ksp_max_it 1 -snes_linesearch_type basic -mat_coloring_type natural",
           1) == 0;

using reference::PetscPattern;
using reference::PetscSnesOptions;
using reference::PetscSnesResult;
using reference::PetscSnesSolver;

using test::invalid_argument_of;

// F_i = x_i³ + 2 x_i − x_{i−1} − x_{i+1} − 1 (x_{−1} = x_n = 0): monotone, one root; Jacobian
// tridiagonal.
void chain(const Eigen::VectorXd& x, Eigen::VectorXd& f) {
  const Eigen::Index n = x.size();
  f.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    f[i] = x[i] * x[i] * x[i] + 2.0 * x[i] - 1.0;
    if (i > 0) f[i] -= x[i - 1];
    if (i + 1 < n) f[i] -= x[i + 1];
  }
}

PetscPattern tridiagonal(int n) {
  PetscPattern p;
  p.row_starts.push_back(0);
  for (int i = 0; i < n; ++i) {
    for (int j = std::max(0, i - 1); j <= std::min(n - 1, i + 1); ++j) p.columns.push_back(j);
    p.row_starts.push_back(static_cast<long>(p.columns.size()));
  }
  return p;
}

class PetscReference : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(kHostileEnvironment);
    if (!reference::petsc_available()) GTEST_SKIP() << "nlobs built without PETSc";
  }
};

TEST_F(PetscReference, NewtonLsSolvesAChainOnItsPatternWithColouredDifferences) {
  const int n = 200;
  PetscSnesSolver snes(n, {}, chain, tridiagonal(n));
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  const PetscSnesResult r = snes.solve(x);
  EXPECT_TRUE(r.success) << r.status() << " " << r.reason_name << " " << r.reason_text;
  EXPECT_EQ(r.status(), "converged");
  EXPECT_GT(r.reason, 0);
  Eigen::VectorXd f;
  chain(x, f);
  EXPECT_LT(f.lpNorm<Eigen::Infinity>(), 1e-9);
  EXPECT_DOUBLE_EQ(r.residual, f.lpNorm<Eigen::Infinity>());
  EXPECT_GT(r.iterations, 0);
  EXPECT_GT(r.linear_iterations, 0);
  EXPECT_GT(r.jacobian_evaluations, 0);
  // A tridiagonal pattern takes 3 colours: each Jacobian costs 3 evaluations (and F at x is
  // PETSc's own), far below n.
  EXPECT_LT(r.evaluations, 10 * r.jacobian_evaluations + 10);
  EXPECT_GE(r.evaluations, 3 * r.jacobian_evaluations);  // the colouring's evaluations counted
  // solve() runs again from a new start, counts afresh.
  Eigen::VectorXd again = Eigen::VectorXd::Constant(n, 2.0);
  const PetscSnesResult r2 = snes.solve(again);
  EXPECT_TRUE(r2.success);
  EXPECT_LT((again - x).lpNorm<Eigen::Infinity>(), 1e-8);
}

TEST_F(PetscReference, WithoutAPatternTheJacobianIsDense) {
  const auto circle = [](const Eigen::VectorXd& x, Eigen::VectorXd& f) {
    f.resize(2);
    f << x[0] * x[0] + x[1] * x[1] - 4.0, x[0] - x[1];
  };
  for (const char* type : {"newtonls", "newtontr"}) {
    PetscSnesOptions o;
    o.type = type;
    PetscSnesSolver snes(2, o, circle);
    Eigen::VectorXd x(2);
    x << 1.0, 0.5;
    const PetscSnesResult r = snes.solve(x);
    EXPECT_TRUE(r.success) << type << ": " << r.status();
    EXPECT_NEAR(x[0], std::sqrt(2.0), 1e-9) << type;
    EXPECT_NEAR(x[1], std::sqrt(2.0), 1e-9) << type;
  }
  // Without a pattern, n is bounded: n² entries.
  EXPECT_NE(invalid_argument_of([&] { PetscSnesSolver(2001, {}, chain); }).find("n <= 2000"),
            std::string::npos);
}

// -ksp_type preonly with a direct LU: one linear "iteration" per Newton step, as GMRES with
// ILU(0) (exact on a tridiagonal matrix); GMRES without a preconditioner takes more. Options
// reach PETSc, one solver only.
TEST_F(PetscReference, OptionsReachPetscAndOnlyTheirSolver) {
  const int n = 300;
  const PetscSnesOptions direct =
      PetscSnesSolver::parse_name("petsc:newtonls:-ksp_type=preonly:-pc_type=lu");
  ASSERT_EQ(direct.type, "newtonls");
  ASSERT_EQ(direct.options.size(), 2u);
  EXPECT_EQ(direct.options[0].first, "-ksp_type");
  EXPECT_EQ(direct.options[0].second, "preonly");
  PetscSnesSolver lu(n, direct, chain, tridiagonal(n));
  PetscSnesSolver none(n, PetscSnesSolver::parse_name("petsc:newtonls:-pc_type=none"), chain,
                       tridiagonal(n));
  PetscSnesSolver plain(n, {}, chain, tridiagonal(n));  // made after `none`: not its options
  Eigen::VectorXd x1 = Eigen::VectorXd::Zero(n), x2 = x1, x4 = x1;
  const PetscSnesResult a = lu.solve(x1);
  const PetscSnesResult b = plain.solve(x2);
  const PetscSnesResult d = none.solve(x4);
  ASSERT_TRUE(a.success && b.success && d.success);
  EXPECT_EQ(a.linear_iterations, a.iterations);
  EXPECT_EQ(b.linear_iterations, b.iterations);
  EXPECT_GT(d.linear_iterations, 2 * d.iterations);
  // A flag without a value: matrix-free Newton–Krylov (PETSc's J·v by differences), which
  // takes no preconditioner from a matrix (on a shorter chain: unpreconditioned GMRES(30) stalls
  // on the n = 300 one, whose J has condition number ~1e4 at 0).
  const PetscSnesOptions mf = PetscSnesSolver::parse_name("petsc:newtonls:-snes_mf:-pc_type=none");
  ASSERT_EQ(mf.options.size(), 2u);
  EXPECT_EQ(mf.options[0].second, "");
  PetscSnesSolver free(30, mf, chain, tridiagonal(30));
  Eigen::VectorXd x3 = Eigen::VectorXd::Zero(30);
  const PetscSnesResult c = free.solve(x3);
  EXPECT_TRUE(c.success) << c.status();
  EXPECT_EQ(c.jacobian_evaluations, 0);  // matrix-free: J·v by differences, no matrix
  // The line search takes the solver's options too: full Newton steps (basic) on the chain from
  // 0 overshoot to |x| ~ 1e4, where the backtracking default (b above) does not.
  PetscSnesSolver basic(n,
                        PetscSnesSolver::parse_name("petsc:newtonls:-snes_linesearch_type=basic"),
                        chain, tridiagonal(n));
  Eigen::VectorXd x5 = Eigen::VectorXd::Zero(n);
  const PetscSnesResult e = basic.solve(x5);
  EXPECT_FALSE(e.success);
  EXPECT_EQ(e.status(), "diverged_dtol") << e.reason_name;
}

TEST_F(PetscReference, MisspeltUnknownAndHostileOptionsAreRefusedByName) {
  const int n = 10;
  const auto make = [&](const std::string& name) {
    return invalid_argument_of(
        [&] { PetscSnesSolver(n, PetscSnesSolver::parse_name(name), chain, tridiagonal(n)); });
  };
  EXPECT_NE(make("petsc:newtonls:-ksp_tyep=gmres").find("-ksp_tyep"), std::string::npos);
  // What PETSc reads only while it solves (monitors, reasons, views) is taken.
  EXPECT_EQ(make("petsc:newtonls:-ksp_converged_reason:-snes_converged_reason"), "<accepted>");
  EXPECT_NE(make("petsc:nosuchtype").find("nosuchtype"), std::string::npos);
  EXPECT_NE(make("petsc:newtonls:-ksp_type=nosuchksp").find("nosuchksp"), std::string::npos);
  // No option may name a file or leave the solver's families.
  EXPECT_NE(make("petsc:newtonls:-snes_view=/etc/passwd").find("a value is"), std::string::npos);
  EXPECT_NE(make("petsc:newtonls:-snes_linesearch_type=nosuchls").find("nosuchls"),
            std::string::npos);
  // Viewers that write files, open windows or sockets; what would bypass the row's name.
  for (const char* refused :
       {"petsc:newtonls:-snes_view=binary", "petsc:newtonls:-ksp_view=hdf5",
        "petsc:newtonls:-snes_view=socket", "petsc:newtonls:-ksp_view_mat",
        "petsc:newtonls:-snes_monitor_lg_residualnorm", "petsc:newtonls:-snes_type=qn",
        "petsc:newtonls:-snes_fd", "petsc:newtonls:-snes_fd_color"}) {
    EXPECT_NE(make(refused).find("PETSc option"), std::string::npos) << refused;
  }
  EXPECT_EQ(make("petsc:newtonls:-snes_monitor=ascii"), "<accepted>");
  EXPECT_NE(make("petsc:newtonls:-log_view").find("a key is"), std::string::npos);
  EXPECT_NE(make("petsc:newtonls:-snes_monitor=").find("has no value"), std::string::npos);
  EXPECT_NE(make("petsc:").find("SNES type"), std::string::npos);
  EXPECT_NE(make("petsc:NewtonLS").find("SNES type"), std::string::npos);
  EXPECT_NE(
      invalid_argument_of([] { PetscSnesSolver::parse_name("kinsol:newton"); }).find("petsc:TYPE"),
      std::string::npos);
  // Options out of range.
  PetscSnesOptions o;
  o.max_evaluations = 1;
  EXPECT_NE(invalid_argument_of([&] {
              PetscSnesSolver(n, o, chain, tridiagonal(n));
            }).find("max_evaluations"),
            std::string::npos);
  o = {};
  o.absolute_tolerance = std::nan("");
  EXPECT_NE(
      invalid_argument_of([&] { PetscSnesSolver(n, o, chain, tridiagonal(n)); }).find("tolerances"),
      std::string::npos);
}

TEST_F(PetscReference, MalformedPatternsAreRefused) {
  PetscPattern p = tridiagonal(4);
  p.row_starts.pop_back();
  EXPECT_NE(invalid_argument_of([&] { PetscSnesSolver(4, {}, chain, p); }).find("n + 1"),
            std::string::npos);
  p = tridiagonal(4);
  std::swap(p.columns[3], p.columns[4]);  // row 1: 1, 0, 2
  EXPECT_NE(invalid_argument_of([&] { PetscSnesSolver(4, {}, chain, p); }).find("row 1"),
            std::string::npos);
  p = tridiagonal(4);
  p.columns.back() = 4;  // column n
  EXPECT_NE(invalid_argument_of([&] { PetscSnesSolver(4, {}, chain, p); }).find("row 3"),
            std::string::npos);
}

// ILU(0), PETSc's default, needs the diagonal in the structure: it is added to a pattern
// without it (x₁ = 1, x₀ = 2, an anti-diagonal Jacobian). Its zero pivot is then ILU's named
// failure, not an error about the matrix; without a preconditioner GMRES solves it.
TEST_F(PetscReference, APatternWithoutItsDiagonalIsNamedByTheLinearSolver) {
  PetscPattern anti;
  anti.row_starts = {0, 1, 2};
  anti.columns = {1, 0};
  const auto f = [](const Eigen::VectorXd& x, Eigen::VectorXd& out) {
    out.resize(2);
    out << x[1] - 1.0, x[0] - 2.0;
  };
  PetscSnesSolver ilu(2, {}, f, anti);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(2);
  const PetscSnesResult r = ilu.solve(x);
  EXPECT_EQ(r.status(), "diverged_linear_solve") << r.error;
  PetscSnesSolver none(2, PetscSnesSolver::parse_name("petsc:newtonls:-pc_type=none"), f, anti);
  x.setZero();
  EXPECT_TRUE(none.solve(x).success);
  EXPECT_NEAR(x[0], 2.0, 1e-9);
  EXPECT_NEAR(x[1], 1.0, 1e-9);
}

TEST_F(PetscReference, TheBudgetStopsTheRunBeforeFIsCalled) {
  const int n = 50;
  long calls = 0;
  PetscSnesOptions o;
  o.max_evaluations = 4;
  PetscSnesSolver snes(
      n, o,
      [&calls](const Eigen::VectorXd& x, Eigen::VectorXd& f) {
        ++calls;
        chain(x, f);
      },
      tridiagonal(n));
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  const PetscSnesResult r = snes.solve(x);
  EXPECT_EQ(r.status(), "max_evaluations");
  EXPECT_FALSE(r.success);
  EXPECT_LE(r.evaluations, 4);
  EXPECT_EQ(calls, r.evaluations);
  EXPECT_NE(r.error.find("budget"), std::string::npos) << r.error;
  // The budget ran out inside PETSc's coloured differences (the 4th evaluation): the next solve
  // starts clean, from the root itself.
  chain(x, x);  // any x; then the root from a good start
  Eigen::VectorXd root = Eigen::VectorXd::Zero(n);
  PetscSnesSolver(n, {}, chain, tridiagonal(n)).solve(root);
  Eigen::VectorXd again = root;
  const PetscSnesResult r2 = snes.solve(again);
  EXPECT_TRUE(r2.success) << r2.status() << " " << r2.error;
}

TEST_F(PetscReference, NanAndAThrowingFAreNamedNotConverged) {
  const int n = 5;
  PetscSnesSolver nan_f(
      n, {},
      [](const Eigen::VectorXd& x, Eigen::VectorXd& f) {
        f = Eigen::VectorXd::Constant(x.size(), std::nan(""));
      },
      tridiagonal(n));
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  const PetscSnesResult r = nan_f.solve(x);
  EXPECT_FALSE(r.success);
  EXPECT_EQ(r.status(), "diverged_fnorm_nan") << r.reason_name << " " << r.error;

  // F throws at its 3rd call only: inside the coloured differences of the first Jacobian.
  int call = 0;
  PetscSnesSolver throws(
      n, {},
      [&call](const Eigen::VectorXd& v, Eigen::VectorXd& f) {
        if (++call == 3) throw std::runtime_error("boom");
        chain(v, f);
      },
      tridiagonal(n));
  x.setZero();
  EXPECT_THROW((void)throws.solve(x), std::runtime_error);
  // The solver stays usable after it: PETSc's objects are made anew.
  x.setZero();
  const PetscSnesResult after = throws.solve(x);
  EXPECT_TRUE(after.success) << after.status() << " " << after.error;
  Eigen::VectorXd wrong(3);
  EXPECT_NE(invalid_argument_of([&] { (void)nan_f.solve(wrong); }).find("size 3"),
            std::string::npos);
}

// In the suite, a user's set beside our engine; a misspelt option is that row's invalid_input.
TEST_F(PetscReference, RunsInTheSuiteOnAUsersProblem) {
  auto cubic_chain = [](const auto& x, auto& f) {
    using std::max;
    for (Index i = 0; i < x.size(); ++i) {
      f[i] = x[i] * x[i] * x[i] + 2.0 * x[i] - 1.0;
      if (i > 0) f[i] -= x[i - 1];
      if (i + 1 < x.size()) f[i] -= x[i + 1];
    }
  };
  const Index n = 3000;  // above the dense limit: the pattern is detected
  ProblemSetEntry set{.name = "petsc-chain", .description = "a cubic chain"};
  const std::vector<TestProblem> problems = {
      root_test_problem("cubic-chain", n, cubic_chain, {{"zero", Eigen::VectorXd::Zero(n)}})};
  const auto rows = reference::run_suite(
      set, problems, {"petsc:newtonls", "newton:linesearch=1", "petsc:newtonls:-ksp_tyep=gmres"});
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_TRUE(rows[0].solved) << rows[0].status << " " << rows[0].message;
  EXPECT_GT(rows[0].j_evals, 0);
  EXPECT_TRUE(rows[1].solved) << rows[1].status;
  EXPECT_EQ(rows[2].status, "invalid_input");
  EXPECT_NE(rows[2].message.find("-ksp_tyep"), std::string::npos) << rows[2].message;
  const auto refs = reference::all_reference_solvers();
  EXPECT_NE(std::find(refs.begin(), refs.end(), "petsc:newtonls"), refs.end());
}

// MINPACK's test problems (the suite's mgh set) with PETSc's two Newton types: statuses are
// lower-case names, and PETSc solves most of them from MINPACK's starts.
TEST_F(PetscReference, StatusesOnTheMghSetAreLowerCaseNames) {
  const ProblemSelection mgh = select_problems("mgh", problem_set_registry());
  const auto rows =
      reference::run_suite(*mgh.set, mgh.problems, {"petsc:newtonls", "petsc:newtontr"});
  std::map<std::string, int> solved;
  for (const reference::SuiteRow& r : rows) {
    solved[r.solver] += r.solved;
    EXPECT_EQ(r.status.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789_"),
              std::string::npos)
        << r.solver << " " << r.problem << ": '" << r.status << "'";
  }
  EXPECT_GE(solved["petsc:newtonls"], 30) << "of " << rows.size() / 2;
  EXPECT_GE(solved["petsc:newtontr"], 30) << "of " << rows.size() / 2;
}

}  // namespace
}  // namespace nlobs
