// The MGH suite problems (against their known roots and finite differences) and the runner.
#include <gtest/gtest.h>

#include <cmath>

#include "nlobs/reference/problem_suite.hpp"
#include "nlobs/registry/problem_sets/mgh_problems.hpp"
#include "nlobs/solvers/finite_difference.hpp"

namespace nlobs::reference {
namespace {

TEST(Mgh, NineteenCasesInMinpacksOrder) {
  const auto cases = mgh_cases();
  ASSERT_EQ(cases.size(), 19U);
  EXPECT_EQ(cases.front().name, "rosenbrock");
  EXPECT_EQ(cases.back().name, "broyden_banded");
  int chebyquad = 0;
  for (const auto& c : cases) chebyquad += c.name == "chebyquad";
  EXPECT_EQ(chebyquad, 5);
}

TEST(Mgh, KnownRootsGiveZeroResidual) {
  struct Known {
    int number, n;
    Eigen::VectorXd root;
  };
  const std::vector<Known> known = {
      {1, 2, Eigen::VectorXd::Ones(2)},   {2, 4, Eigen::VectorXd::Zero(4)},
      {4, 4, Eigen::VectorXd::Ones(4)},   {5, 3, (Eigen::VectorXd(3) << 1.0, 0.0, 0.0).finished()},
      {8, 10, Eigen::VectorXd::Ones(10)}, {12, 10, Eigen::VectorXd::Ones(10)},
  };
  for (const Known& k : known) {
    const MghCase c = mgh_case(k.number, k.n);
    Eigen::VectorXd f(k.n);
    c.problem.evaluate(k.root, f);
    EXPECT_LT(f.lpNorm<Eigen::Infinity>(), 1e-14) << c.name;
  }
}

TEST(Mgh, TheSetsKnownSolutionsAreRootsAndItsStartsTheStandardOnes) {
  const std::vector<TestProblem> problems = build_problem_set(*problem_set_registry().find("mgh"));
  const auto cases = mgh_cases();
  ASSERT_EQ(problems.size(), cases.size());
  int with_solutions = 0;
  for (size_t k = 0; k < problems.size(); ++k) {
    const TestProblem& p = problems[k];
    EXPECT_EQ(p.name, cases[k].name);
    ASSERT_EQ(p.starts.size(), 3u);
    EXPECT_EQ(p.starts[2].label, "x100");
    EXPECT_EQ(p.starts[2].x, cases[k].start(100.0));
    for (const Eigen::VectorXd& s : p.solutions) {
      Eigen::VectorXd f(p.size());
      p.residual.evaluate(s, f);
      EXPECT_LT(f.norm(), 1e-12) << p.name;
      ++with_solutions;
    }
  }
  EXPECT_EQ(with_solutions, 7);  // Wood lists two: its minimum and a second root of grad f
}

TEST(Mgh, StandardStartsAndScaling) {
  EXPECT_EQ(mgh_case(1, 2).start(10.0), Eigen::Vector2d(-12.0, 10.0));
  EXPECT_EQ(mgh_case(6, 6).start(1.0), Eigen::VectorXd::Zero(6));
  EXPECT_EQ(mgh_case(6, 6).start(100.0), Eigen::VectorXd::Constant(6, 100.0));  // initpt rule
  EXPECT_NEAR(mgh_case(7, 5).start(1.0)[4], 5.0 / 6.0, 1e-15);
  EXPECT_THROW(mgh_case(7, 4), std::invalid_argument);
}

TEST(Mgh, AutodiffJacobiansMatchFiniteDifferences) {
  // Also the regression test for run-time-size AD with constants mixed in (T(0.0) in the
  // tridiagonal and integral-equation problems).
  for (const MghCase& c : mgh_cases()) {
    Eigen::VectorXd x = c.start(1.0) + 0.01 * Eigen::VectorXd::LinSpaced(c.n, 0.1, 1.0);
    Eigen::VectorXd f(c.n), fp(c.n), fm(c.n);
    Eigen::MatrixXd ad, fd;
    c.problem.jacobian(x, ad);
    c.problem.evaluate(x, f);
    FiniteDifferenceWorkspace<Dynamic> w;
    w.resize(c.n);
    finite_difference_jacobian<Dynamic, Dynamic>(
        [&c](const Eigen::VectorXd& a, Eigen::VectorXd& o) { c.problem.evaluate(a, o); }, x, f, fd,
        FiniteDifference::kCentral, w, fp, fm);
    EXPECT_LT((ad - fd).cwiseAbs().maxCoeff(), 1e-6 * std::max(1.0, fd.cwiseAbs().maxCoeff()))
        << c.name << " n=" << c.n;
  }
}

TEST(MghSuite, RunsAndJudgesEverySolverTheSameWay) {
  SuiteOptions options;
  options.starts = {"x1"};
  const std::vector<std::string> solvers = {"ceres",         "newton:linesearch=1", "minpack:hybrj",
                                            "kinsol:newton", "gsl:hybridsj",        "gsl:gnewton",
                                            "picard"};
  const ProblemSelection mgh = select_problems("mgh", problem_set_registry());
  const auto rows = run_suite(*mgh.set, mgh.problems, solvers, options);
  ASSERT_EQ(rows.size(), 19U * solvers.size());
  int ceres = 0, hybrj = 0;
  for (const SuiteRow& r : rows) {
    EXPECT_EQ(r.solved, r.residual <= 1e-8) << r.problem << ' ' << r.solver;
    EXPECT_EQ(r.set, "mgh");
    EXPECT_EQ(r.start, "x1");
    // The error column is there exactly for the problems with known solutions.
    const bool known = r.problem == "rosenbrock" || r.problem == "wood" ||
                       r.problem == "powell_singular" || r.problem == "helical_valley" ||
                       r.problem == "brown_almost_linear" || r.problem == "variably_dimensioned";
    EXPECT_EQ(std::isnan(r.error), !known) << r.problem;
    // (Wood's and Brown's square systems have other roots: from x1 every solver finds Wood's
    // other one, 1.97 away; Powell singular's root is approached like sqrt|F|.)
    const bool unique = r.problem == "rosenbrock" || r.problem == "helical_valley";
    if (unique && r.solved) {
      EXPECT_LT(r.error, 1e-6) << r.problem << ' ' << r.solver;
    }
    EXPECT_GT(r.ns, 0.0);
    if (r.problem == "rosenbrock" && r.solver != "picard") {
      EXPECT_TRUE(r.solved) << r.solver;
    }
    ceres += r.solver == "ceres" && r.solved;
    hybrj += r.solver == "minpack:hybrj" && r.solved;
  }
  // From the standard starts, both solve most of the suite.
  EXPECT_GE(ceres, 14);
  EXPECT_GE(hybrj, 14);
  EXPECT_THROW(run_suite(*mgh.set, mgh.problems, {"bogus"}, options), std::invalid_argument);
}

TEST(MghSuite, SplitsSpecLists) {
  using V = std::vector<std::string>;
  EXPECT_EQ(split_spec_list("anderson:m=3,damping=0.5,newton"),
            (V{"anderson:m=3,damping=0.5", "newton"}));
  EXPECT_EQ(split_spec_list("ceres:dogleg,nlopt:LD_SLSQP,xtol_rel=1e-6"),
            (V{"ceres:dogleg", "nlopt:LD_SLSQP,xtol_rel=1e-6"}));
  EXPECT_EQ(split_spec_list("picard,,aitken"), (V{"picard", "aitken"}));
}

}  // namespace
}  // namespace nlobs::reference
