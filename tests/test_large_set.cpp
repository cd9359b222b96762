// The built-in set "large" (registry/src/problem_sets/large_set.cpp) and the suite at sizes the
// dense solvers cannot hold: sizes chosen at run time (large:n=K), the Jacobians' patterns
// detected from the unchanged generic F, KINSOL's band, KLU and SPGMR forms beside our engines,
// kinLaplace_bnd's and kinFoodWeb_kry's published counts reproduced, and what is refused (sizes out
// of range, a set of fixed sizes asked for one, a dense problem above the dense limit, a dense
// reference on a large problem).
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
                                                 {"laplace2d", 400},
                                                 {"food-web", 384}};  // 6 species, 8 × 8
  EXPECT_EQ(sizes(at_400.problems), expected);
  // 1001: a 32 × 32 grid (√1001 ≈ 31.6), 500 points of two species, 6 species on 13 × 13.
  const std::map<std::string, Index> odd = {{"broyden-tridiagonal", 1001},
                                            {"bratu2d", 1024},
                                            {"reaction-diffusion1d", 1000},
                                            {"laplace2d", 1024},
                                            {"food-web", 1014}};
  EXPECT_EQ(sizes(select_problems("large:n=1001", problem_set_registry()).problems), odd);
  const auto one = select_problems("large/bratu2d:n=1001", problem_set_registry()).problems;
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one[0].size(), 1024);
  // Without :n=K: about 10⁴, kinLaplace_bnd's own 31 × 31 and kinFoodWeb_kry's own 8 × 8.
  const std::map<std::string, Index> defaults = {{"broyden-tridiagonal", 10000},
                                                 {"bratu2d", 10000},
                                                 {"reaction-diffusion1d", 10000},
                                                 {"laplace2d", 961},
                                                 {"food-web", 384}};
  EXPECT_EQ(sizes(select_problems("large", problem_set_registry()).problems), defaults);
}

TEST(LargeSet, EveryPatternIsDetectedFromTheGenericF) {
  // The stencils: 3 entries a row at most (Broyden), 5 (Bratu, Laplace), 4 (two species: the
  // species' own 3-point stencil and the other species at the same point), 8 (the food web: a
  // species' 5-point stencil and the three species of the other kind at the same point).
  const std::map<std::string, Index> widest_row = {{"broyden-tridiagonal", 3},
                                                   {"bratu2d", 5},
                                                   {"reaction-diffusion1d", 4},
                                                   {"laplace2d", 5},
                                                   {"food-web", 8}};
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
  // The food web has its own test (below): its scaled norms and positivity make another story.
  std::vector<SuiteRow> rows = run_large("large:n=400", solvers);
  std::erase_if(rows, [](const SuiteRow& r) { return r.problem == "food-web"; });
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

// kinFoodWeb_kry's interaction rates at one mesh point (its WebRate: the dot product with a's
// row over all six species, zeros included), written again here from the example's constants,
// independently of the problem set's F.
void food_web_rates(double x, double y, const double* c, double* rates) {
  for (int i = 0; i < 6; ++i) {
    double dot = 0.0;
    for (int j = 0; j < 6; ++j) {
      const double a = j == i ? -1.0 : (i < 3 && j >= 3) ? -0.5e-6 : (i >= 3 && j < 3) ? 1e4 : 0.0;
      dot += c[j] * a;
    }
    rates[i] = c[i] * ((i < 3 ? 1.0 : -1.0) * (1.0 + 1.0 * x * y) + dot);
  }
}

// SUNDIALS' dense LU as the example calls it (SUNDlsMat_denseGETRF / GETRS: column-major,
// partial pivoting, multipliers by the pivot's reciprocal), so that the preconditioner is the
// example's to the last bit.
struct Block6 {
  double a[6][6];  // a[column][row]
  int pivot[6];
  void factor() {
    for (int k = 0; k < 6; ++k) {
      int l = k;
      for (int i = k + 1; i < 6; ++i) {
        if (std::abs(a[k][i]) > std::abs(a[k][l])) l = i;
      }
      pivot[k] = l;
      if (l != k) {
        for (int i = 0; i < 6; ++i) std::swap(a[i][l], a[i][k]);
      }
      const double mult = 1.0 / a[k][k];
      for (int i = k + 1; i < 6; ++i) a[k][i] *= mult;
      for (int j = k + 1; j < 6; ++j) {
        const double akj = a[j][k];
        if (akj != 0.0) {
          for (int i = k + 1; i < 6; ++i) a[j][i] -= akj * a[k][i];
        }
      }
    }
  }
  void solve(double* b) const {
    for (int k = 0; k < 6; ++k) {
      if (pivot[k] != k) std::swap(b[k], b[pivot[k]]);
    }
    for (int k = 0; k < 5; ++k) {
      for (int i = k + 1; i < 6; ++i) b[i] -= a[k][i] * b[k];
    }
    for (int k = 5; k > 0; --k) {
      b[k] /= a[k][k];
      for (int i = 0; i < k; ++i) b[i] -= a[k][i] * b[k];
    }
    b[0] /= a[0][0];
  }
};

// SUNDIALS' kinFoodWeb_kry.out: nni = 9, nli = 329, nfe = 10, nfeSG = 338, nps = 338, npe = 1,
// ncfl = 6; KINSOL as the example runs it (SPGMR, maxl 15, 2 restarts, right-preconditioned by
// the interaction-only block-diagonal P, its blocks by difference quotients of the rates; no
// line search, u > 0, u_scale = f_scale = 1 for prey and 1e-5 for predators, fnormtol 1e-7,
// scsteptol 1e-13) on the set's F; and the printed corner concentrations, which our Newton
// (with the problem's scaling) finds too.
TEST(LargeSet, KinsolSpgmrReproducesKinFoodWebKrysPublishedCounts) {
  const auto problems = select_problems("large/food-web", problem_set_registry()).problems;
  ASSERT_EQ(problems.size(), 1u);
  const TestProblem& p = problems[0];
  const int n = 384, mesh = 8;
  ASSERT_EQ(p.size(), n);
  const double d = 1.0 / (mesh - 1);
  std::vector<Block6> blocks(mesh * mesh);
  reference::KinsolOptions o;
  o.strategy = reference::KinsolStrategy::kNewtonLineSearch;
  o.line_search = false;
  o.linear_solver = reference::KinsolLinearSolver::kSpgmr;
  o.max_setup_calls = 0;  // KINSOL's default, 10
  o.tolerance = 1e-7;
  o.step_tolerance = 1e-13;
  o.constraints = Eigen::VectorXd::Constant(n, 2.0);
  o.u_scale = p.u_scale;
  o.f_scale = p.f_scale;
  // PrecSetupBD: the blocks ∂rates/∂c by difference quotients, increments as the example's.
  o.preconditioner.setup = [&](auto u, auto u_scale, auto f, auto f_scale) {
    const double uround = std::numeric_limits<double>::epsilon();
    double sum = 0.0;  // N_VWL2Norm(f, f_scale)
    for (int i = 0; i < n; ++i) {
      const double product = f[i] * f_scale[i];
      sum += product * product;
    }
    double r0 = 1000.0 * uround * std::sqrt(sum) * n;
    if (r0 == 0.0) r0 = 1.0;
    for (int jy = 0; jy < mesh; ++jy) {
      for (int jx = 0; jx < mesh; ++jx) {
        const int point = jx + mesh * jy;
        double c[6], rates[6], perturbed[6];
        for (int s = 0; s < 6; ++s) c[s] = u[6 * point + s];
        food_web_rates(d * jx, d * jy, c, rates);
        for (int j = 0; j < 6; ++j) {
          const double saved = c[j];
          const double r =
              std::max(std::sqrt(uround) * std::abs(saved), r0 / u_scale[6 * point + j]);
          c[j] += r;
          const double inverse = 1.0 / r;
          food_web_rates(d * jx, d * jy, c, perturbed);
          c[j] = saved;
          for (int i = 0; i < 6; ++i) blocks[point].a[j][i] = (perturbed[i] - rates[i]) * inverse;
        }
        blocks[point].factor();
      }
    }
    return 0;
  };
  o.preconditioner.solve = [&](auto, auto, auto, auto, Eigen::Map<Eigen::VectorXd> v) {
    for (int point = 0; point < mesh * mesh; ++point) blocks[point].solve(v.data() + 6 * point);
    return 0;
  };
  reference::KinsolSolver kinsol(
      n, o, [&p](const Eigen::VectorXd& x, Eigen::VectorXd& f) { p.residual.evaluate(x, f); });
  Eigen::VectorXd x = p.starts[0].x;
  const reference::KinsolResult r = kinsol.solve(x);
  EXPECT_EQ(r.status(), "converged") << r.flag_name << " " << r.reason;
#if defined(__x86_64__) && !defined(__FMA__)
  // To the iteration: rounding alone moves these counts (Debian's SUNDIALS 6.4 on x86-64, no
  // fused multiply-add there or here).
  EXPECT_EQ(r.iterations, 9);
  EXPECT_EQ(r.linear_iterations, 329);
  EXPECT_EQ(r.product_evaluations, 338);
  EXPECT_EQ(r.evaluations, 10 + 338 + 1);  // KINSOL's, its J·v quotients', our check's
  EXPECT_EQ(r.preconditioner_setups, 1);
  EXPECT_EQ(r.preconditioner_solves, 338);
  EXPECT_EQ(r.linear_convergence_failures, 6);
#else
  EXPECT_GE(r.iterations, 6);
  EXPECT_LE(r.iterations, 12);
  EXPECT_EQ(r.preconditioner_setups, 1);
#endif
  // "At bottom left: 1.16428 ... 34927.5; at top right: 1.25797 ... 37736.7".
  const Eigen::Index top_right = 6 * (mesh * mesh - 1);
  for (const Eigen::VectorXd* answer : {&x}) {
    for (int s = 0; s < 3; ++s) {
      EXPECT_NEAR((*answer)[s], 1.16428, 5e-6);
      EXPECT_NEAR((*answer)[s + 3], 34927.5, 0.05);
      EXPECT_NEAR((*answer)[top_right + s], 1.25797, 5e-6);
      EXPECT_NEAR((*answer)[top_right + s + 3], 37736.7, 0.05);
    }
  }
  // In the suite, with the problem's scaling and box: our Newton and KINSOL's sparse forms.
  const auto rows =
      run_large("large/food-web", {"newton:linesearch=1", "kinsol:newton-klu", "pseudo-transient"});
  ASSERT_EQ(rows.size(), 3u);
  for (const SuiteRow& row : rows) {
    SCOPED_TRACE(row.solver + " " + row.status + " " + row.message);
    if (row.solver == "pseudo-transient") {
      // The residual flow with these scales does not reach the root: named, not "converged".
      EXPECT_FALSE(row.solved);
      EXPECT_NE(row.status, "converged");
      continue;
    }
    EXPECT_TRUE(row.solved);
    EXPECT_LE((row.x - x).cwiseQuotient(x).lpNorm<Eigen::Infinity>(), 1e-9);
  }
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
  // Constraints of another size or code; a preconditioner without SPGMR, or half of one.
  reference::KinsolOptions c;
  c.strategy = reference::KinsolStrategy::kNewtonLineSearch;
  c.constraints = Eigen::VectorXd::Constant(3, 2.0);
  EXPECT_NE(invalid_argument_of([&] { reference::KinsolSolver(4, c, f); }).find("size n = 4"),
            std::string::npos);
  c.constraints = Eigen::VectorXd::Constant(4, 3.0);
  EXPECT_NE(invalid_argument_of([&] { reference::KinsolSolver(4, c, f); }).find("constraints[0]"),
            std::string::npos);
  c.constraints.resize(0);
  c.preconditioner.solve = [](auto, auto, auto, auto, Eigen::Map<Eigen::VectorXd>) { return 0; };
  EXPECT_NE(invalid_argument_of([&] { reference::KinsolSolver(4, c, f); }).find("preconditioner"),
            std::string::npos);
  c.linear_solver = reference::KinsolLinearSolver::kSpgmr;  // still no setup
  EXPECT_NE(invalid_argument_of([&] { reference::KinsolSolver(4, c, f); }).find("both setup"),
            std::string::npos);
  c.step_tolerance = -1.0;
  EXPECT_NE(invalid_argument_of([&] { reference::KinsolSolver(4, c, f); }).find("step_tolerance"),
            std::string::npos);
}

}  // namespace
}  // namespace nlobs
