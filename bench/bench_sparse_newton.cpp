// Newton's sparse path end to end (problem built, solved from the start): a pattern declared
// against the same problem written as an unchanged RootProblem::with_autodiff, whose pattern is
// detected at x₀ (sparse/sparsity_detection.hpp) — issue 40's target: within 1.5× at n = 10⁵.
// Broyden's tridiagonal function from −1 (band-lu) and 2-D Bratu, λ = 6, from 0 (klu). Then
// pseudo-transient continuation on Bratu, detected, with klu and with BiCGSTAB + ILU(0).
#include <benchmark/benchmark.h>

#include "large_test_problems.hpp"
#include "nlobs/solvers/newton_engine.hpp"
#include "nlobs/solvers/pseudo_transient_engine.hpp"
#include "nlobs/solvers/root_adapter.hpp"
#include "nlobs/solvers/sparse/sparse_problem.hpp"

namespace {

using nlobs::Dynamic;
using nlobs::Index;

enum Pattern { kDeclared, kDetected };

nlobs::Summary solve(const nlobs::RootProblem<>& problem, Eigen::VectorXd& x) {
  nlobs::SolverOptions options;
  options.stop.residual_tolerance = 1e-10;
  nlobs::NewtonEngine<> newton(nlobs::NewtonOptions{.line_search = true}, options);
  return newton.solve(nlobs::to_fixed_point(problem), x);
}

template <typename F>
void run(benchmark::State& state, F f, Index n, const nlobs::SparsityPattern& pattern, double x0) {
  const bool detected = state.range(1) == kDetected;
  int steps = 0;
  for (auto _ : state) {
    Eigen::VectorXd x = Eigen::VectorXd::Constant(n, x0);
    const nlobs::RootProblem<> problem = detected ? nlobs::RootProblem<>::with_autodiff(f, n, n)
                                                  : nlobs::sparse_autodiff_problem(f, pattern);
    const nlobs::Summary s = solve(problem, x);
    if (s.status != nlobs::Status::kConverged || s.linear_solver.empty()) {
      state.SkipWithError("not solved on the sparse path");
      return;
    }
    steps = s.iterations;
    benchmark::DoNotOptimize(x.data());
  }
  state.SetLabel(detected ? "detected" : "declared");
  state.counters["n"] = static_cast<double>(n);
  state.counters["steps"] = steps;
}

void BM_NewtonBroydenTridiagonal(benchmark::State& state) {
  const Index n = state.range(0);
  run(state, nlobs::test::broyden_tridiagonal(), n, nlobs::SparsityPattern::band(n, 1, 1), -1.0);
}
BENCHMARK(BM_NewtonBroydenTridiagonal)
    ->ArgsProduct({{10000, 100000}, {kDeclared, kDetected}})
    ->Unit(benchmark::kMillisecond);

void BM_NewtonBratu(benchmark::State& state) {
  const Index s = state.range(0), n = s * s;
  auto f = nlobs::test::bratu(s);
  const nlobs::SparsityPattern pattern = nlobs::detect_sparsity(f, Eigen::VectorXd::Zero(n), n);
  run(state, f, n, pattern, 0.0);
}
BENCHMARK(BM_NewtonBratu)
    ->ArgsProduct({{100, 316}, {kDeclared, kDetected}})
    ->Unit(benchmark::kMillisecond);

void BM_PseudoTransientBratu(benchmark::State& state) {
  const Index s = state.range(0), n = s * s;
  const bool krylov = state.range(1) == 1;
  nlobs::SolverOptions options;
  options.stop.residual_tolerance = 1e-10;
  nlobs::PseudoTransientOptions ptc;
  ptc.linear_solver = krylov ? "bicgstab:preconditioner=ilu0" : "klu";
  int steps = 0;
  for (auto _ : state) {
    Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
    nlobs::PseudoTransientEngine<> engine(ptc, options);
    const nlobs::Summary r = engine.solve(
        nlobs::to_fixed_point(nlobs::RootProblem<>::with_autodiff(nlobs::test::bratu(s), n, n)), x);
    if (r.status != nlobs::Status::kConverged || r.linear_solver.empty()) {
      state.SkipWithError("not solved on the sparse path");
      return;
    }
    steps = r.iterations;
    benchmark::DoNotOptimize(x.data());
  }
  state.SetLabel(ptc.linear_solver);
  state.counters["n"] = static_cast<double>(n);
  state.counters["steps"] = steps;
}
BENCHMARK(BM_PseudoTransientBratu)
    ->ArgsProduct({{100, 316}, {0, 1}})
    ->Unit(benchmark::kMillisecond);

}  // namespace
