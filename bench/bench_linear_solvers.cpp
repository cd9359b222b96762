// The linear solvers of nlobs/solvers/linear/ on the Jacobians of two problems nlobs' engines
// must solve at scale: 2-D Bratu (PETSc's SNES ex5, λ = 6, 5-point stencil, at u = 0.1) and
// Broyden's tridiagonal function (at x = −1), each Jacobian from the compressed AD path. One
// iteration = setup (factor / build the preconditioner) + one solve to ‖b − Jx‖ ≤ 1e-8 ‖b‖:
// one Newton step's linear algebra.
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <memory>
#include <string>

#include "large_test_problems.hpp"
#include "nlobs/common/invalid_input.hpp"
#include "nlobs/solvers/linear/linear_solver.hpp"
#include "nlobs/solvers/linear/make_linear_solver.hpp"
#include "nlobs/solvers/sparse/compressed_jacobian.hpp"

namespace {

using nlobs::Index;

constexpr std::array<const char*, 11> kSolvers = {"dense-lu",
                                                  "band-lu",
                                                  "sparse-lu",
                                                  "klu",
                                                  "gmres",
                                                  "gmres:preconditioner=jacobi",
                                                  "gmres:preconditioner=ilu0",
                                                  "gmres:preconditioner=ilut",
                                                  "bicgstab:preconditioner=ilu0",
                                                  "umfpack",
                                                  "gmres:preconditioner=boomeramg"};

// J = ∂f(x) by the compressed AD path, the pattern detected at x.
template <typename F>
nlobs::SparseJacobian compressed_jacobian_at(F f, const Eigen::VectorXd& x) {
  nlobs::CompressedJacobian cj(nlobs::detect_sparsity(f, x, x.size()));
  nlobs::SparseJacobian jac;
  cj.autodiff(f, x, jac);
  return jac;
}

nlobs::SparseJacobian bratu_jacobian(Index s) {
  return compressed_jacobian_at(nlobs::test::bratu(s), Eigen::VectorXd::Constant(s * s, 0.1));
}

nlobs::SparseJacobian broyden_tridiagonal_jacobian(Index n) {
  return compressed_jacobian_at(nlobs::test::broyden_tridiagonal(),
                                Eigen::VectorXd::Constant(n, -1.0));
}

void run(benchmark::State& state, const nlobs::SparseJacobian& jac) {
  const std::string spec = kSolvers[static_cast<std::size_t>(state.range(0))];
  state.SetLabel(spec);
  std::unique_ptr<nlobs::LinearSolver> solver;
  try {
    solver = nlobs::make_linear_solver(spec);
  } catch (const nlobs::InvalidInput& e) {  // boomeramg in a build without hypre
    state.SkipWithError(e.what());
    return;
  }
  const Eigen::VectorXd b = Eigen::VectorXd::Ones(jac.rows());
  Eigen::VectorXd x;
  for (auto _ : state) {
    if (solver->setup(jac) != nlobs::LinearStatus::kSolved ||
        solver->solve(b, x, 1e-8) != nlobs::LinearStatus::kSolved) {
      state.SkipWithError(solver->message().c_str());
      break;
    }
    benchmark::DoNotOptimize(x.data());
  }
  state.counters["n"] = static_cast<double>(jac.rows());
  if (solver->iterative() && solver->stats().solves > 0) {
    state.counters["linear_iterations"] =
        static_cast<double>(solver->stats().iterations) / solver->stats().solves;
  }
}

void BM_LinearSolveBratu(benchmark::State& state) {
  run(state, bratu_jacobian(state.range(1)));
}
// Grid side s (n = s²): 32 (≈ 10³), 100 (10⁴), 316 (≈ 10⁵), 1000 (10⁶); dense LU only at
// s = 32, band LU (width s, O(s³·s) = O(n²) work) up to 10⁴, multigrid alone at 10⁶.
BENCHMARK(BM_LinearSolveBratu)
    ->ArgsProduct({{0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10}, {32}})
    ->ArgsProduct({{1, 2, 3, 4, 5, 6, 7, 8, 9, 10}, {100}})
    ->ArgsProduct({{2, 3, 5, 6, 7, 8, 9, 10}, {316}})
    ->ArgsProduct({{10}, {1000}})
    ->Unit(benchmark::kMillisecond);

void BM_LinearSolveBroydenTridiagonal(benchmark::State& state) {
  run(state, broyden_tridiagonal_jacobian(state.range(1)));
}
BENCHMARK(BM_LinearSolveBroydenTridiagonal)
    ->ArgsProduct({{1, 2, 3, 6, 9, 10}, {10000, 100000, 1000000}})
    ->Unit(benchmark::kMillisecond);

}  // namespace
