// The engines beside newton on the sparse path. Pseudo-transient continuation: δ⁻¹I + J
// assembled on J's pattern and solved by each kind of linear solver, on problems nlobs does not
// ship (2-D Bratu, PETSc's SNES ex5; a system whose shifted matrix is singular at δ₀); the same
// iterations and root as the dense path, the linear solver in the Summary, the named failures
// and refusals. auto: on a large problem with a sparse Jacobian, the stages without a sparse
// path are not run (said in the message), below dense_stage_limit they are.
#include <gtest/gtest.h>

#include <string>
#include <type_traits>
#include <vector>

#include "large_test_problems.hpp"
#include "nlobs/solvers/builtin_engines.hpp"
#include "nlobs/solvers/engine_registry.hpp"
#include "nlobs/solvers/pseudo_transient_engine.hpp"
#include "nlobs/solvers/root_adapter.hpp"
#include "nlobs/solvers/sparse/sparse_jacobian.hpp"
#include "nlobs/solvers/sparse/sparse_problem.hpp"
#include "test_support.hpp"

namespace nlobs {
namespace {

Summary flow(const RootProblem<>& problem, Vector<Dynamic>& x, PseudoTransientOptions ptc = {}) {
  PseudoTransientEngine<> engine(ptc, test::residual_stop(1e-9, 200));
  return engine.solve(to_fixed_point(problem), x);
}

// The engine a spec names, from the process-wide registry, on problem from x.
Summary by_spec(const std::string& spec, const RootProblem<>& problem, Vector<Dynamic>& x) {
  return EngineRegistry<Dynamic>::global()
      .create(spec, test::residual_stop(1e-9, 200))
      ->solve(to_fixed_point(problem), x);
}

TEST(SparsePseudoTransient, FollowsTheDensePathOnBratuWithDirectAndKrylovSolvers) {
  const Index s = 20, n = s * s;  // bandwidth 20 > 16: auto is klu
  const Vector<Dynamic> x0 = Vector<Dynamic>::Zero(n);
  const auto problem = RootProblem<>::with_autodiff(test::bratu(s), n, n);
  Vector<Dynamic> dense = x0;
  const Summary d = flow(problem.with_dense_jacobian(), dense);
  ASSERT_EQ(d.status, Status::kConverged) << d.message;
  EXPECT_TRUE(d.linear_solver.empty());

  Vector<Dynamic> direct = x0;
  const Summary k = flow(problem, direct);
  ASSERT_EQ(k.status, Status::kConverged) << k.message;
  EXPECT_EQ(k.linear_solver, "klu");
  EXPECT_EQ(k.iterations, d.iterations);
  EXPECT_EQ(k.linear_setups, k.iterations) << "one δ⁻¹I + J per step: no singular retries";
  EXPECT_LE((direct - dense).lpNorm<Eigen::Infinity>(), 1e-10);

  for (const std::string linear :
       {"band-lu", "sparse-lu", "gmres:preconditioner=ilu0", "bicgstab:preconditioner=ilu0"}) {
    Vector<Dynamic> x = x0;
    PseudoTransientOptions options;
    options.linear_solver = linear;
    const Summary r = flow(problem, x, options);
    ASSERT_EQ(r.status, Status::kConverged) << linear << ": " << r.message;
    EXPECT_LE((x - dense).lpNorm<Eigen::Infinity>(), 1e-8) << linear;
    EXPECT_EQ(r.linear_iterations > 0, linear.find("gmres") == 0 || linear.find("bicgstab") == 0)
        << linear;
  }
}

// F_i = x_i² − 1 (+ a weak coupling, so that J is not diagonal): at x = −50, J ≈ −100 I, and
// δ⁻¹I + J is singular at δ₀ = 10⁻².
auto squares() {
  return [](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    const Index n = x.size();
    Vector<Dynamic, T> f(n);
    for (Index i = 0; i < n; ++i) f[i] = x[i] * x[i] - 1.0;
    for (Index i = 0; i + 1 < n; ++i) f[i] += 0.0 * x[i + 1];
    return f;
  };
}

TEST(SparsePseudoTransient, NamesASingularShiftedMatrixAsTheDensePathDoes) {
  const Index n = 150;
  const Vector<Dynamic> x0 = Vector<Dynamic>::Constant(n, -50.0);
  const auto problem = RootProblem<>::with_autodiff(squares(), n, n);
  PseudoTransientOptions pinned;  // δ may not be halved away from the singularity
  pinned.initial_pseudo_step = pinned.min_pseudo_step = 1e-2;
  for (const bool sparse : {false, true}) {
    Vector<Dynamic> x = x0;
    const Summary r = flow(sparse ? problem : problem.with_dense_jacobian(), x, pinned);
    EXPECT_EQ(r.status, Status::kSingularJacobian) << sparse << ": " << r.message;
    EXPECT_NE(r.message.find("delta^-1 I + J at iteration 1 (delta 0.01): "), std::string::npos)
        << r.message;
    EXPECT_NE(r.message.find("singular"), std::string::npos) << r.message;
    EXPECT_EQ(r.linear_solver, sparse ? "band-lu" : "") << r.message;
    EXPECT_EQ(x, x0) << "the last good point is kept";
  }
}

TEST(SparsePseudoTransient, FollowsTheFixedPointFlowOnTheSparsePath) {
  // −(Bratu): J negative definite, so the fixed-point flow ẋ = +F is the stable one.
  const Index s = 20, n = s * s;
  auto negated = [bratu = test::bratu(s)](const auto& u, auto& f) mutable {
    bratu(u, f);
    for (Index i = 0; i < f.size(); ++i) f[i] = -f[i];
  };
  const auto problem = RootProblem<>::with_autodiff(negated, n, n);
  PseudoTransientOptions fixed_point;
  fixed_point.flow = PseudoTransientOptions::Flow::kFixedPoint;
  Vector<Dynamic> dense = Vector<Dynamic>::Zero(n), sparse = dense;
  const Summary d = flow(problem.with_dense_jacobian(), dense, fixed_point);
  const Summary k = flow(problem, sparse, fixed_point);
  ASSERT_EQ(d.status, Status::kConverged) << d.message;
  ASSERT_EQ(k.status, Status::kConverged) << k.message;
  EXPECT_EQ(k.linear_solver, "klu");
  EXPECT_EQ(k.iterations, d.iterations);
  EXPECT_LE((sparse - dense).lpNorm<Eigen::Infinity>(), 1e-10);
}

TEST(SparsePseudoTransient, HalvesDeltaPastASingularShiftedMatrixAndConverges) {
  // F_i = x_i² − 1 at x = −0.25 with δ₀ = 2: δ⁻¹I + J = 0.5 I − 0.5 I = 0 exactly; at δ = 1 the
  // flow goes on to the root 1.
  const Index n = 150;
  const auto problem = RootProblem<>::with_autodiff(squares(), n, n);
  PseudoTransientOptions wide;
  wide.initial_pseudo_step = 2.0;
  Summary runs[2];
  for (const bool sparse : {false, true}) {
    Vector<Dynamic> x = Vector<Dynamic>::Constant(n, -0.25);
    const Summary r = flow(sparse ? problem : problem.with_dense_jacobian(), x, wide);
    ASSERT_EQ(r.status, Status::kConverged) << sparse << ": " << r.message;
    EXPECT_LE((x.array() - 1.0).abs().maxCoeff(), 1e-9);
    EXPECT_EQ(r.message.find("singular"), std::string::npos)
        << "a retried trial leaves no message: " << r.message;
    runs[sparse] = r;
  }
  EXPECT_EQ(runs[1].iterations, runs[0].iterations);
  EXPECT_EQ(runs[1].linear_setups, runs[1].iterations + 1) << "the singular trial, then one a step";
}

TEST(SparsePseudoTransient, TakesAScalingAndRefusesWhatTheSparsePathCannotTake) {
  const Index n = 120;
  const Vector<Dynamic> x0 = Vector<Dynamic>::Zero(n);
  // A scaling on a declared sparse Jacobian keeps the sparse path (D_f J D_u⁻¹), on the dense
  // path's flow: the same steps.
  const auto declared = sparse_autodiff_problem(test::broyden_tridiagonal(), x0);
  Vector<Dynamic> x = x0;
  std::vector<Summary> runs;
  for (const bool sparse : {false, true}) {
    PseudoTransientEngine<> scaled({}, test::residual_stop(1e-9, 400));
    scaled.set_scaling({.u_scale = Vector<Dynamic>::Constant(n, 2.0)});
    x = x0;
    runs.push_back(
        scaled.solve(to_fixed_point(sparse ? declared : declared.with_dense_jacobian()), x));
    EXPECT_EQ(runs.back().status, Status::kConverged) << sparse << ": " << runs.back().message;
    EXPECT_EQ(runs.back().linear_solver.empty(), !sparse);
  }
  EXPECT_EQ(runs[1].iterations, runs[0].iterations);
  x = x0;
  // A user's sparse Jacobian whose pattern lacks a diagonal entry, where δ⁻¹ is added.
  std::vector<std::pair<Index, Index>> off_diagonal;
  for (Index i = 0; i + 1 < n; ++i) off_diagonal.push_back({i, i + 1});
  auto pattern =
      std::make_shared<const SparsityPattern>(SparsityPattern::from_entries(n, n, off_diagonal));
  const auto f = [](const Vector<Dynamic>& v) { return Vector<Dynamic>(v); };
  const auto user = RootProblem<>::from_map(f, n, n).with_sparse_jacobian(
      {pattern, [](const Vector<Dynamic>&, const Vector<Dynamic>&, SparseJacobian&) { return 0; },
       0});
  PseudoTransientEngine<> engine({}, test::residual_stop(1e-9, 200));
  EXPECT_EQ(test::message_of([&] { engine.solve(to_fixed_point(user), x); }),
            "pseudo-transient: the sparse Jacobian's pattern lacks the diagonal entry (0, 0), "
            "where delta^-1 I is added (the problems of sparse_problem.hpp have every one)");
  // A user's evaluate that returns another structure than its pattern.
  auto tridiagonal = std::make_shared<const SparsityPattern>(SparsityPattern::band(n, 1, 1));
  const auto wrong = RootProblem<>::from_map(f, n, n).with_sparse_jacobian(
      {tridiagonal,
       [n](const Vector<Dynamic>&, const Vector<Dynamic>&, SparseJacobian& jac) {
         jac.resize(n, n);  // no entries
         return 0;
       },
       0});
  x = Vector<Dynamic>::Ones(n);  // (F(x) = x: not solved at the start)
  EXPECT_EQ(test::message_of([&] { engine.solve(to_fixed_point(wrong), x); }),
            "the sparse Jacobian's evaluate returned a 120x120 matrix with 0 stored entries, not "
            "the structure of its pattern (120x120, 358 entries)");
  // Options.
  PseudoTransientOptions bad;
  bad.linear_tolerance = 1.0;
  EXPECT_THROW(PseudoTransientEngine<>{bad}, InvalidInput);
  bad = {};
  bad.linear_solver = "lu-of-my-own";
  EXPECT_THROW(PseudoTransientEngine<>{bad}, InvalidInput);
}

TEST(SparsePseudoTransient, IsReachableByEngineSpec) {
  const Index s = 12, n = s * s;
  auto& registry = EngineRegistry<Dynamic>::global();
  auto engine = registry.create("pseudo-transient:linear=gmres,preconditioner=ilu0",
                                test::residual_stop(1e-9, 200));
  Vector<Dynamic> x = Vector<Dynamic>::Zero(n);
  const Summary r =
      engine->solve(to_fixed_point(RootProblem<>::with_autodiff(test::bratu(s), n, n)), x);
  ASSERT_EQ(r.status, Status::kConverged) << r.message;
  EXPECT_EQ(r.linear_solver, "gmres");
  EXPECT_GT(r.linear_iterations, 0);
  EXPECT_THROW(
      registry.create("pseudo-transient:preconditioner=ilu0", test::residual_stop(1e-9, 200)),
      InvalidInput);
  EXPECT_THROW(registry.create("pseudo-transient:linear=nonsense", test::residual_stop(1e-9, 200)),
               InvalidInput);
  // UMFPACK's ordering, by spec; ordering= belongs to linear=umfpack only.
  for (const char* spec : {"pseudo-transient:linear=umfpack,ordering=metis",
                           "newton:linesearch=1,linear=umfpack,ordering=metis"}) {
    auto by_spec = registry.create(spec, test::residual_stop(1e-9, 200));
    Vector<Dynamic> y = Vector<Dynamic>::Zero(n);
    const Summary u =
        by_spec->solve(to_fixed_point(RootProblem<>::with_autodiff(test::bratu(s), n, n)), y);
    ASSERT_EQ(u.status, Status::kConverged) << spec << ": " << u.message;
    EXPECT_EQ(u.linear_solver, "umfpack") << spec;
  }
  EXPECT_NE(test::message_of([&] {
              registry.create("newton:linear=klu,ordering=metis", test::residual_stop(1e-9, 9));
            }).find("ordering=metis needs linear_solver=umfpack"),
            std::string::npos);
  EXPECT_THROW(registry.create("newton:linear=umfpack,ordering=rcm", test::residual_stop(1e-9, 9)),
               InvalidInput);
}

TEST(SparseAuto, RunsOnlyTheStagesWithASparsePathOnALargeSparseProblem) {
  auto& registry = EngineRegistry<Dynamic>::global();
  const Index n = 3000;
  const Vector<Dynamic> x0 = Vector<Dynamic>::Constant(n, -1.0);
  const auto problem = RootProblem<>::with_autodiff(test::broyden_tridiagonal(), n, n);
  // The default order: newton solves it on the sparse path; the stages after it are not reached.
  Vector<Dynamic> x = x0;
  const Summary a = by_spec("auto", problem, x);
  ASSERT_EQ(a.status, Status::kConverged) << a.message;
  EXPECT_EQ(a.stage, "newton");
  EXPECT_EQ(a.linear_solver, "band-lu");
  EXPECT_EQ(a.message, "");

  // dogleg and newton's trust region first: not run (a dense 3000×3000 J), said so;
  // pseudo-transient solves it.
  x = x0;
  const Summary b = by_spec("auto:order=dogleg/newton:trustregion=1/pseudo-transient", problem, x);
  ASSERT_EQ(b.status, Status::kConverged) << b.message;
  EXPECT_EQ(b.stage, "pseudo-transient");
  EXPECT_EQ(b.linear_solver, "band-lu");
  EXPECT_EQ(b.message,
            "after dogleg, newton:trustregion=1 not run (no sparse path, and n = 3000 > "
            "dense_stage_limit 1000)");
  // levenberg-marquardt has one (the normal equations by CHOLMOD), and so has broyden
  // (limited memory).
  x = x0;
  const Summary c = by_spec("auto:order=dogleg/levenberg-marquardt", problem, x);
  ASSERT_EQ(c.status, Status::kConverged) << c.message;
  EXPECT_EQ(c.stage, "levenberg-marquardt");
  EXPECT_EQ(c.linear_solver, "cholmod");
  EXPECT_EQ(c.message,
            "after dogleg not run (no sparse path, and n = 3000 > dense_stage_limit 1000)");
  x = x0;
  const Summary d = by_spec("auto:order=dogleg/broyden", problem, x);
  ASSERT_EQ(d.status, Status::kConverged) << d.message;
  EXPECT_EQ(d.stage, "broyden");
  EXPECT_EQ(d.linear_solver, "band-lu");
  EXPECT_THROW(registry.create("auto:dense_limit=-1", test::residual_stop(1e-9, 200)),
               InvalidInput);
}

TEST(SparseAuto, RunsDenseStagesBelowTheLimitWithoutOneOrWhenNoneHasASparsePath) {
  const Index n = 300;  // detected (≥ 100), below the default dense_stage_limit 1000
  const Vector<Dynamic> x0 = Vector<Dynamic>::Constant(n, -1.0);
  const auto problem = RootProblem<>::with_autodiff(test::broyden_tridiagonal(), n, n);
  for (const std::string spec :
       {"auto:order=dogleg", "auto:order=dogleg,dense_limit=0",
        "auto:order=dogleg,dense_limit=100" /* no stage with a sparse path: all run */}) {
    Vector<Dynamic> x = x0;
    const Summary r = by_spec(spec, problem, x);
    ASSERT_EQ(r.status, Status::kConverged) << spec << ": " << r.message;
    EXPECT_EQ(r.stage, "dogleg") << spec;
    EXPECT_TRUE(r.linear_solver.empty()) << "dogleg's dense J";
    EXPECT_EQ(r.message, "") << spec;
  }
  Vector<Dynamic> x = x0;
  const Summary r = by_spec("auto:order=dogleg/pseudo-transient,dense_limit=100", problem, x);
  ASSERT_EQ(r.status, Status::kConverged) << r.message;
  EXPECT_EQ(r.stage, "pseudo-transient");
  EXPECT_EQ(r.message,
            "after dogleg not run (no sparse path, and n = 300 > dense_stage_limit 100)");
}

}  // namespace
}  // namespace nlobs
