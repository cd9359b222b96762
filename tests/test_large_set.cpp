// The built-in set "large" (registry/src/problem_sets/large_set.cpp) and the suite at sizes the
// dense solvers cannot hold: sizes chosen at run time (large:n=K), the Jacobians' patterns
// detected from the unchanged generic F, KINSOL's band, KLU and SPGMR forms beside our engines,
// kinLaplace_bnd's published counts reproduced, and what is refused (sizes out of range, a set
// of fixed sizes asked for one, a dense problem above the dense limit, a dense reference on a
// large problem).
#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "invalid_argument_message.hpp"
#include "nlobs/reference/kinsol_solver.hpp"
#include "nlobs/reference/problem_suite.hpp"
#include "nlobs/registry/problem_sets.hpp"
#include "nlobs/solvers/sparse/sparse_jacobian.hpp"
#include "nlobs/solvers/sparse/sparsity_pattern.hpp"
#include "test_support.hpp"

namespace nlobs {
namespace {

using reference::SuiteRow;

std::string selection_error(const std::string& selector) {
  try {
    select_problems(selector, problem_set_registry());
  } catch (const InvalidInput& e) {
    return e.what();
  }
  return "<accepted>";
}

using test::invalid_argument_of;

std::map<std::string, Index> sizes(const std::vector<TestProblem>& problems) {
  std::map<std::string, Index> out;
  for (const TestProblem& p : problems) out[p.name] = p.size();
  return out;
}

TEST(LargeSet, BuildsEachProblemAtTheSizeNearestK) {
  const ProblemSelection at_400 = select_problems("large:n=400", problem_set_registry());
  const std::map<std::string, Index> expected = {{"broyden-tridiagonal", 400},
                                                 {"bratu2d", 400},  // 20 × 20
                                                 {"reaction-diffusion1d", 400},
                                                 {"laplace2d", 400}};
  EXPECT_EQ(sizes(at_400.problems), expected);
  // 1001: a 32 × 32 grid (√1001 ≈ 31.6), 500 points of two species.
  const std::map<std::string, Index> odd = {{"broyden-tridiagonal", 1001},
                                            {"bratu2d", 1024},
                                            {"reaction-diffusion1d", 1000},
                                            {"laplace2d", 1024}};
  EXPECT_EQ(sizes(select_problems("large:n=1001", problem_set_registry()).problems), odd);
  const auto one = select_problems("large/bratu2d:n=1001", problem_set_registry()).problems;
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one[0].size(), 1024);
  // Without :n=K: about 10⁴, and kinLaplace_bnd's own 31 × 31.
  const std::map<std::string, Index> defaults = {{"broyden-tridiagonal", 10000},
                                                 {"bratu2d", 10000},
                                                 {"reaction-diffusion1d", 10000},
                                                 {"laplace2d", 961}};
  EXPECT_EQ(sizes(select_problems("large", problem_set_registry()).problems), defaults);
}

TEST(LargeSet, EveryPatternIsDetectedFromTheGenericF) {
  // The stencils: 3 entries a row at most (Broyden), 5 (Bratu, Laplace), 4 (two species: the
  // species' own 3-point stencil and the other species at the same point).
  const std::map<std::string, Index> widest_row = {
      {"broyden-tridiagonal", 3}, {"bratu2d", 5}, {"reaction-diffusion1d", 4}, {"laplace2d", 5}};
  for (const TestProblem& p : select_problems("large:n=900", problem_set_registry()).problems) {
    SCOPED_TRACE(p.name);
    const SparseJacobianSource* source = p.residual.sparse_jacobian(p.starts[0].x);
    ASSERT_NE(source, nullptr) << p.residual.sparse_jacobian_note();
    const SparsityPattern& pattern = *source->pattern;
    Index widest = 0;
    for (Index i = 0; i < pattern.rows; ++i) {
      widest = std::max(widest, pattern.row_start[i + 1] - pattern.row_start[i]);
    }
    EXPECT_EQ(widest, widest_row.at(p.name));
    // The sparse Jacobian is the dense AD one.
    Eigen::MatrixXd dense(p.size(), p.size());
    const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(p.size(), -0.5, 0.7);
    p.residual.jacobian(x, dense);
    Eigen::VectorXd f(p.size());
    p.residual.evaluate(x, f);
    SparseJacobian sparse;
    source->evaluate(x, f, sparse);
    EXPECT_LE((Eigen::MatrixXd(sparse) - dense).lpNorm<Eigen::Infinity>(),
              1e-12 * dense.lpNorm<Eigen::Infinity>());
  }
}

TEST(LargeSet, RefusesSizesItCannotBuild) {
  EXPECT_NE(selection_error("large:n=0").find("is not in 1 .. 10000000"), std::string::npos)
      << selection_error("large:n=0");
  EXPECT_NE(selection_error("large:n=20000000").find("is not in 1 .. 10000000"), std::string::npos);
  EXPECT_NE(selection_error("large:n=-5").find("':n=K'"), std::string::npos);
  EXPECT_NE(selection_error("large/bratu2d:n=ten").find("':n=K'"), std::string::npos);
  EXPECT_NE(selection_error("mgh:n=5").find("has fixed sizes"), std::string::npos)
      << selection_error("mgh:n=5");
  EXPECT_NE(selection_error("large:n=").find("':n=K'"), std::string::npos);
  EXPECT_NE(selection_error("large/:n=5").find("has no problem ':n=5'"), std::string::npos)
      << selection_error("large/:n=5");
  EXPECT_NE(selection_error("large:n=5/x").find("unknown problem set 'large:n=5'"),
            std::string::npos)
      << selection_error("large:n=5/x");
  const std::string missing = selection_error("large/bratu:n=400");
  EXPECT_NE(missing.find("has no problem 'bratu:n=400'"), std::string::npos) << missing;
  EXPECT_NE(missing.find("bratu2d:n=400"), std::string::npos) << missing;
}

// A user's problem of 2 500 unknowns whose every F_i reads every x_j: its Jacobian is dense, and
// no solver of the suite should be handed 50 MB matrices it did not ask for.
TEST(LargeSet, ADenseProblemAboveTheDenseLimitIsRefusedWithDetectionsReason) {
  const Index n = 2500;
  auto all_coupled = [](const auto& x, auto& out) {
    const auto mean = x.sum() / static_cast<double>(x.size());
    for (Index i = 0; i < x.size(); ++i) out[i] = x[i] - 0.5 * mean - 1.0;
  };
  const TestProblem p =
      root_test_problem("all-coupled", n, all_coupled, {{"x0", Eigen::VectorXd::Zero(n)}});
  const std::string m = test::message_of([&] { validate_test_problem(p, "set 'user'"); });
  EXPECT_NE(m.find("above the limit of 2000 unknowns for a dense Jacobian"), std::string::npos)
      << m;
  EXPECT_NE(m.find("a row of J has more than"), std::string::npos) << m;
  // The same size with a sparse F is accepted.
  auto diagonal = [](const auto& x, auto& out) {
    for (Index i = 0; i < x.size(); ++i) out[i] = x[i] * x[i] - 4.0;
  };
  EXPECT_NO_THROW(validate_test_problem(
      root_test_problem("diagonal", n, diagonal, {{"x0", Eigen::VectorXd::Ones(n)}}), "user"));
}

std::vector<SuiteRow> run_large(const std::string& selector,
                                const std::vector<std::string>& solvers) {
  const ProblemSelection s = select_problems(selector, problem_set_registry());
  return reference::run_suite(*s.set, s.problems, solvers);
}

TEST(LargeSet, KinsolsSparseFormsAndOurSparseEnginesSolveEveryProblem) {
  const std::vector<std::string> solvers = {"newton:linesearch=1", "pseudo-transient",
                                            "pseudo-transient:flow=fixed-point",
                                            "kinsol:newton-band", "kinsol:newton-klu"};
  const auto rows = run_large("large:n=400", solvers);
  ASSERT_EQ(rows.size(), 4u * solvers.size());
  for (const SuiteRow& r : rows) {
    SCOPED_TRACE(r.problem + " " + r.solver + " " + r.status + " " + r.message);
    if (r.solver.rfind("pseudo-transient", 0) == 0) {
      // The default flow dx/dt = −F(x) needs ∂F with eigenvalues of positive real part (Broyden
      // tridiagonal, Bratu, reaction-diffusion), flow=fixed-point (dx/dt = F) negative ones
      // (kinLaplace_bnd's Δ_h + (1 − 3u²) I): the other flow is unstable and must end as a
      // named failure, never a wrong "converged".
      const bool negative_definite = r.problem == "laplace2d";
      const bool suited = (r.solver == "pseudo-transient") != negative_definite;
      EXPECT_EQ(r.solved, suited);
      if (!suited) {
        EXPECT_EQ(r.status, "stagnated");
      } else {
        EXPECT_GE(r.j_evals, 1);
      }
      continue;
    }
    EXPECT_TRUE(r.solved);
    EXPECT_LE(r.residual, 1e-8);
    EXPECT_GE(r.j_evals, 1);
  }
  // The same root from every solver (each problem has one: the monotone ones provably).
  std::map<std::string, Eigen::VectorXd> first;
  for (const SuiteRow& r : rows) {
    if (!r.solved) continue;
    auto [it, inserted] = first.emplace(r.problem, r.x);
    if (!inserted) {
      EXPECT_LE((r.x - it->second).lpNorm<Eigen::Infinity>(), 1e-7) << r.solver;
    }
  }
}

TEST(LargeSet, DenseReferencesAreNotRunAboveTheDenseLimitAndSaySo) {
  const auto rows = run_large("large/broyden-tridiagonal:n=2500",
                              {"minpack:hybrj", "gsl:gnewton", "kinsol:newton",
                               "kinsol:newton-band", "kinsol:newton-spgmr", "newton"});
  ASSERT_EQ(rows.size(), 6u);
  for (const SuiteRow& r : rows) {
    SCOPED_TRACE(r.solver + " " + r.status + " " + r.message);
    if (r.solver == "minpack:hybrj" || r.solver == "gsl:gnewton" || r.solver == "kinsol:newton") {
      EXPECT_EQ(r.status, "invalid_input");
      EXPECT_NE(r.message.find("keeps dense n x n matrices: not run at n = 2500"),
                std::string::npos);
      EXPECT_FALSE(r.solved);
    } else {
      EXPECT_TRUE(r.solved);
    }
  }
}

TEST(LargeSet, KluWithoutASparseJacobianIsAnInvalidInputRow) {
  // mgh/rosenbrock has n = 2: detection declines below 100 unknowns, so KLU has no pattern; band
  // takes the full band and solves it.
  const ProblemSelection s = select_problems("mgh/rosenbrock", problem_set_registry());
  const auto rows =
      reference::run_suite(*s.set, s.problems, {"kinsol:newton-klu", "kinsol:newton-band"});
  ASSERT_FALSE(rows.empty());
  for (const SuiteRow& r : rows) {
    SCOPED_TRACE(r.solver + " " + r.start + " " + r.status + " " + r.message);
    if (r.solver == "kinsol:newton-klu") {
      EXPECT_EQ(r.status, "invalid_input");
      EXPECT_NE(r.message.find("needs a sparse Jacobian"), std::string::npos);
      EXPECT_NE(r.message.find("below 100"), std::string::npos);
    } else {
      EXPECT_NE(r.status, "invalid_input");
    }
  }
}

// ex5's Bratu is F scaled by h²: its slowest mode (eigenvalue ≈ 2π²h²) sets how fast ‖F‖ falls,
// and with it how fast switched evolution relaxation lets δ grow — thousands of steps at n = 400.
// γ = 1.1 (PETSc TSPseudo's increment) grows δ regardless: tens.
TEST(LargeSet, PseudoStepGrowthTakesTheSlowModeInTensOfSteps) {
  const auto rows =
      run_large("large/bratu2d:n=400", {"pseudo-transient", "pseudo-transient:growth=1.1"});
  ASSERT_EQ(rows.size(), 2u);
  for (const SuiteRow& r : rows) EXPECT_TRUE(r.solved) << r.solver << " " << r.status;
  EXPECT_GT(rows[0].f_evals, 1000);
  EXPECT_LT(rows[1].f_evals, 100);
}

// SUNDIALS' kinLaplace_bnd.out: nni = 7, nfe = 8, nje = 1, nfeB = 63 (the difference-quotient
// band Jacobian's evaluations: 2·31 + 1), with modified Newton (mset = 100, msubset = 1),
// fnormtol 1e-12, from 0, on its 31 × 31 grid.
TEST(LargeSet, KinsolBandReproducesKinLaplaceBndsPublishedCounts) {
  const auto problems = select_problems("large/laplace2d", problem_set_registry()).problems;
  ASSERT_EQ(problems.size(), 1u);
  const TestProblem& p = problems[0];
  ASSERT_EQ(p.size(), 961);
  reference::KinsolOptions o;
  o.strategy = reference::KinsolStrategy::kNewtonLineSearch;
  o.linear_solver = reference::KinsolLinearSolver::kBand;
  o.lower_bandwidth = o.upper_bandwidth = 31;
  o.max_setup_calls = 100;
  o.max_sub_setup_calls = 1;
  o.tolerance = 1e-12;
  reference::KinsolSolver kinsol(
      961, o, [&p](const Eigen::VectorXd& x, Eigen::VectorXd& f) { p.residual.evaluate(x, f); });
  Eigen::VectorXd x = Eigen::VectorXd::Zero(961);
  const reference::KinsolResult r = kinsol.solve(x);
  EXPECT_EQ(r.status(), "converged") << r.flag_name << " " << r.reason;
  EXPECT_EQ(r.iterations, 7);
  EXPECT_EQ(r.jacobian_evaluations, 1);
  EXPECT_EQ(r.evaluations, 8 + 63 + 1);  // KINSOL's, its band quotients', our check's
  // The printed solution: u = 0.15564 at the centre (x = y = 0.5, point 16 of 31).
  EXPECT_NEAR(x[15 + 15 * 31], 0.15564, 5e-6);
  EXPECT_NEAR(x[0], 0.00405, 5e-6);
}

// A 2-D grid's band at n = 10⁶ (widths 1000) would take 24 GB of band storage: refused before
// anything is allocated.
TEST(LargeSet, KinsolRefusesABandItCannotStore) {
  reference::KinsolOptions o;
  o.strategy = reference::KinsolStrategy::kNewtonLineSearch;
  o.linear_solver = reference::KinsolLinearSolver::kBand;
  o.lower_bandwidth = o.upper_bandwidth = 1000;
  const std::string m = invalid_argument_of([&] {
    reference::KinsolSolver(1'000'000, o,
                            [](const Eigen::VectorXd& x, Eigen::VectorXd& y) { y = x; });
  });
  EXPECT_NE(m.find("above the limit of 1.25e+08 (1 GB)"), std::string::npos) << m;
  EXPECT_NE(m.find("kinsol:newton-klu"), std::string::npos) << m;
}

// A user's set of run-time size, as docs/extending.md registers it: the selector builds it at n,
// the pattern of its generic F is detected, and the sparse solvers solve it.
TEST(LargeSet, AUsersSetOfRunTimeSizeRunsAtAnyN) {
  auto chain_problems = [](Index n) {
    auto chain = [](const auto& x, auto& f) {
      for (Index i = 0; i < x.size(); ++i) {
        f[i] = x[i] * x[i] - 2.0;
        if (i > 0) f[i] -= 0.1 * x[i - 1];
      }
    };
    return std::vector<TestProblem>{
        root_test_problem("chain", n, chain, {{"ones", Eigen::VectorXd::Ones(n)}})};
  };
  if (!problem_set_registry().find("test-chain")) {
    problem_set_registry().add(
        ProblemSetEntry{.name = "test-chain",
                        .description = "a chain of any size",
                        .problems = [chain_problems] { return chain_problems(1000); },
                        .problems_of_size = chain_problems,
                        .default_solvers = {"newton:linesearch=1", "kinsol:newton-klu"}},
        "test_large_set");
  }
  const ProblemSelection s = select_problems("test-chain:n=5000", problem_set_registry());
  ASSERT_EQ(s.problems.size(), 1u);
  EXPECT_EQ(s.problems[0].size(), 5000);
  EXPECT_EQ(select_problems("test-chain", problem_set_registry()).problems[0].size(), 1000);
  const auto rows = reference::run_suite(*s.set, s.problems, s.set->default_solvers);
  ASSERT_EQ(rows.size(), 2u);
  for (const SuiteRow& r : rows) {
    EXPECT_TRUE(r.solved) << r.solver << " " << r.status << " " << r.message;
  }
  EXPECT_NE(s.problems[0].residual.sparse_jacobian_note().find("detected"), std::string::npos);
}

TEST(LargeSet, KinsolRefusesABadBandOrPattern) {
  const auto f = [](const Eigen::VectorXd& x, Eigen::VectorXd& out) { out = x; };
  reference::KinsolOptions o;
  o.strategy = reference::KinsolStrategy::kNewtonLineSearch;
  o.linear_solver = reference::KinsolLinearSolver::kBand;
  o.lower_bandwidth = 4;  // n = 4: widths 0 .. 3
  EXPECT_NE(
      invalid_argument_of([&] { reference::KinsolSolver(4, o, f); }).find("lower bandwidth 4"),
      std::string::npos);
  o.linear_solver = reference::KinsolLinearSolver::kKlu;
  EXPECT_NE(invalid_argument_of([&] { reference::KinsolSolver(4, o, f); }).find("values function"),
            std::string::npos);
  reference::KinsolSparseJacobian bad;
  bad.row_starts = {0, 1, 2, 3, 4};
  bad.columns = {0, 1, 7, 3};  // a column outside 0 .. 3
  bad.values = [](const Eigen::VectorXd&, const Eigen::VectorXd&, double*) {};
  EXPECT_NE(invalid_argument_of([&] { reference::KinsolSolver(4, o, f, {}, bad); }).find("row 2"),
            std::string::npos);
  bad.row_starts = {0, 100, 2, 3, 4};  // past the columns listed: never read
  EXPECT_NE(
      invalid_argument_of([&] { reference::KinsolSolver(4, o, f, {}, bad); }).find("row_starts"),
      std::string::npos);
  bad.row_starts = {0, 1, 2, 3};  // n + 1 = 5 needed
  EXPECT_NE(invalid_argument_of([&] { reference::KinsolSolver(4, o, f, {}, bad); }).find("n + 1"),
            std::string::npos);
}

}  // namespace
}  // namespace nlobs
