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

#include "nlobs/solvers/linear/linear_solver.hpp"
#include "nlobs/solvers/linear/make_linear_solver.hpp"
#include "nlobs/solvers/sparse/compressed_jacobian.hpp"

namespace {

using nlobs::Index;

constexpr std::array<const char*, 9> kSolvers = {"dense-lu",
                                                 "band-lu",
                                                 "sparse-lu",
                                                 "klu",
                                                 "gmres",
                                                 "gmres:preconditioner=jacobi",
                                                 "gmres:preconditioner=ilu0",
                                                 "gmres:preconditioner=ilut",
                                                 "bicgstab:preconditioner=ilu0"};

nlobs::SparseJacobian bratu_jacobian(Index s) {
  auto f = [s](const auto& u, auto& out) {
    using T = typename std::decay_t<decltype(u)>::Scalar;
    using std::exp;
    const double h2 = 1.0 / static_cast<double>((s + 1) * (s + 1));
    out.resize(s * s);
    for (Index r = 0; r < s; ++r) {
      for (Index c = 0; c < s; ++c) {
        const Index p = r * s + c;
        T sum = 4.0 * u[p];
        if (r > 0) sum -= u[p - s];
        if (r + 1 < s) sum -= u[p + s];
        if (c > 0) sum -= u[p - 1];
        if (c + 1 < s) sum -= u[p + 1];
        out[p] = sum / h2 - 6.0 * exp(u[p]);
      }
    }
  };
  const Eigen::VectorXd u = Eigen::VectorXd::Constant(s * s, 0.1);
  nlobs::CompressedJacobian cj(nlobs::detect_sparsity(f, u, s * s));
  nlobs::SparseJacobian jac;
  cj.autodiff(f, u, jac);
  return jac;
}

nlobs::SparseJacobian broyden_tridiagonal_jacobian(Index n) {
  auto f = [](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    const Index m = x.size();
    nlobs::Vector<nlobs::Dynamic, T> out(m);
    for (Index i = 0; i < m; ++i) {
      out[i] = (3.0 - 2.0 * x[i]) * x[i] + 1.0;
      if (i > 0) out[i] -= x[i - 1];
      if (i + 1 < m) out[i] -= 2.0 * x[i + 1];
    }
    return out;
  };
  const Eigen::VectorXd x = Eigen::VectorXd::Constant(n, -1.0);
  nlobs::CompressedJacobian cj(nlobs::detect_sparsity(f, x, n));
  nlobs::SparseJacobian jac;
  cj.autodiff(f, x, jac);
  return jac;
}

void run(benchmark::State& state, const nlobs::SparseJacobian& jac) {
  const std::string spec = kSolvers[static_cast<std::size_t>(state.range(0))];
  state.SetLabel(spec);
  std::unique_ptr<nlobs::LinearSolver> solver = nlobs::make_linear_solver(spec);
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
// Grid side s (n = s²): 32 (≈ 10³), 100 (10⁴), 316 (≈ 10⁵); dense LU only at s = 32, band LU
// (width s, O(s³·s) = O(n²) work) up to 10⁴.
BENCHMARK(BM_LinearSolveBratu)
    ->ArgsProduct({{0, 1, 2, 3, 4, 5, 6, 7, 8}, {32}})
    ->ArgsProduct({{1, 2, 3, 4, 5, 6, 7, 8}, {100}})
    ->ArgsProduct({{2, 3, 5, 6, 7, 8}, {316}})
    ->Unit(benchmark::kMillisecond);

void BM_LinearSolveBroydenTridiagonal(benchmark::State& state) {
  run(state, broyden_tridiagonal_jacobian(state.range(1)));
}
BENCHMARK(BM_LinearSolveBroydenTridiagonal)
    ->ArgsProduct({{1, 2, 3, 6}, {10000, 100000, 1000000}})
    ->Unit(benchmark::kMillisecond);

}  // namespace
