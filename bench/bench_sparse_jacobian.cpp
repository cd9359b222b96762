// Sparse Jacobians of the 2-D Bratu residual (PETSc's SNES ex5, λ = 6, at u = 0.1) at run-time
// size n = s²: pattern detection, column colouring, the compressed AD Jacobian (one pass of
// 8 directions for its 5 colours) against the dense AD Jacobian (⌈n/8⌉ passes, n² doubles),
// and coloured differences (5 evaluations of F).
#include <benchmark/benchmark.h>

#include <cmath>

#include "large_test_problems.hpp"
#include "nlobs/solvers/autodiff.hpp"
#include "nlobs/solvers/sparse/compressed_jacobian.hpp"
#include "nlobs/solvers/sparse/sparse_jacobian.hpp"

namespace {

using nlobs::Index;

using nlobs::test::bratu;

Eigen::VectorXd start(Index s) {
  return Eigen::VectorXd::Constant(s * s, 0.1);
}

void BM_DetectSparsity(benchmark::State& state) {
  const Index s = state.range(0);
  auto f = bratu(s);
  const Eigen::VectorXd u = start(s);
  for (auto _ : state) benchmark::DoNotOptimize(nlobs::detect_sparsity(f, u, s * s));
  state.counters["n"] = static_cast<double>(s * s);
}
BENCHMARK(BM_DetectSparsity)->Arg(100)->Arg(316)->Unit(benchmark::kMillisecond);

void BM_ColourColumns(benchmark::State& state) {
  const Index s = state.range(0);
  auto f = bratu(s);
  const nlobs::SparsityPattern p = nlobs::detect_sparsity(f, start(s), s * s);
  int colours = 0;
  for (auto _ : state) colours = nlobs::colour_columns(p).colours;
  state.counters["n"] = static_cast<double>(s * s);
  state.counters["colours"] = colours;
}
BENCHMARK(BM_ColourColumns)->Arg(100)->Arg(316)->Unit(benchmark::kMillisecond);

void BM_CompressedAutodiff(benchmark::State& state) {
  const Index s = state.range(0);
  auto f = bratu(s);
  const Eigen::VectorXd u = start(s);
  nlobs::CompressedJacobian cj(nlobs::detect_sparsity(f, u, s * s));
  nlobs::SparseJacobian jac;
  cj.autodiff(f, u, jac);
  for (auto _ : state) {
    cj.autodiff(f, u, jac);
    benchmark::DoNotOptimize(jac.valuePtr());
  }
  state.counters["n"] = static_cast<double>(s * s);
}
BENCHMARK(BM_CompressedAutodiff)->Arg(32)->Arg(100)->Arg(316)->Unit(benchmark::kMillisecond);

void BM_CompressedDifferences(benchmark::State& state) {
  const Index s = state.range(0);
  auto f = bratu(s);
  const Eigen::VectorXd u = start(s);
  nlobs::CompressedJacobian cj(nlobs::detect_sparsity(f, u, s * s));
  Eigen::VectorXd f0;
  f(u, f0);
  nlobs::SparseJacobian jac;
  for (auto _ : state) {
    cj.differences(f, u, f0, jac);
    benchmark::DoNotOptimize(jac.valuePtr());
  }
  state.counters["n"] = static_cast<double>(s * s);
}
BENCHMARK(BM_CompressedDifferences)->Arg(32)->Arg(100)->Arg(316)->Unit(benchmark::kMillisecond);

// Today's path in every Newton-type engine at run-time size: the dense AD Jacobian.
void BM_DenseAutodiff(benchmark::State& state) {
  const Index s = state.range(0);
  auto f = bratu(s);
  const Eigen::VectorXd u = start(s);
  Eigen::MatrixXd jac(s * s, s * s);
  for (auto _ : state) {
    nlobs::autodiff_jacobian<nlobs::Dynamic, nlobs::Dynamic>(f, u, jac);
    benchmark::DoNotOptimize(jac.data());
  }
  state.counters["n"] = static_cast<double>(s * s);
}
BENCHMARK(BM_DenseAutodiff)->Arg(32)->Unit(benchmark::kMillisecond);

}  // namespace
