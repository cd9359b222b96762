// Engines vs one G evaluation vs KINSOL on the modified-Chua window problem ([MGFF23]).
// Each solve benchmark reports its iterations and evaluations as counters; bench_main.cpp
// turns them into the two ratios the foundation issue asks for.
#include <benchmark/benchmark.h>

#include <memory>

#include "nlobs/reference/kinsol_adapter.hpp"
#include "nlobs/registry/problem_sets/chua_window_set.hpp"
#include "nlobs/solvers/solvers.hpp"

namespace {

using nlobs::reference::ChuaWindowCase;
using nlobs::reference::KinsolSolver;
using nlobs::reference::KinsolStrategy;

constexpr double kTolerance = 1e-5;  // the paper's

nlobs::SolverOptions paper_options() {
  nlobs::SolverOptions o;
  o.stop.step_tolerance = kTolerance;
  o.stop.residual_tolerance = kTolerance;  // KINSOL stops on the same two tests
  return o;
}

const ChuaWindowCase& chua() {
  static const ChuaWindowCase c;
  return c;
}

void BM_ChuaG(benchmark::State& state) {
  const ChuaWindowCase& c = chua();
  nlobs::Vector<3> w = c.initial_guess, g;
  for (auto _ : state) {
    c.problem.evaluate(w, g);
    benchmark::DoNotOptimize(g);
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_ChuaG);

// The work a Picard solve must do, without the engine: as many evaluations w ← G(w) as the
// Picard solve takes iterations, in a dependent chain from the same initial guess (each input
// is the previous output, so latency, not throughput, is what counts). Reported per evaluation.
void BM_ChuaGChain(benchmark::State& state) {
  const ChuaWindowCase& c = chua();
  nlobs::PicardEngine<3> picard(paper_options());
  nlobs::Vector<3> w = c.initial_guess, g;
  const int length = picard.solve(c.problem, w).iterations;
  for (auto _ : state) {
    w = c.initial_guess;
    for (int k = 0; k < length; ++k) {
      c.problem.evaluate(w, g);
      w = g;
    }
    benchmark::DoNotOptimize(w);
  }
  state.counters["evaluations"] = length;
  state.SetItemsProcessed(state.iterations() * length);
}
BENCHMARK(BM_ChuaGChain);

void BM_ChuaJacobianAD(benchmark::State& state) {
  const ChuaWindowCase& c = chua();
  nlobs::Vector<3> w = c.initial_guess;
  nlobs::Matrix<3, 3> j;
  for (auto _ : state) {
    c.problem.jacobian(w, j);
    benchmark::DoNotOptimize(j);
  }
}
BENCHMARK(BM_ChuaJacobianAD);

template <typename Engine>
void solve_loop(benchmark::State& state, Engine& engine) {
  const ChuaWindowCase& c = chua();
  nlobs::Summary s;
  for (auto _ : state) {
    nlobs::Vector<3> x = c.initial_guess;
    s = engine.solve(c.problem, x);
    benchmark::DoNotOptimize(x);
  }
  state.counters["iterations"] = s.iterations;
  state.counters["evaluations"] = s.function_evaluations;
  state.counters["converged"] = s.converged();
}

void BM_Picard(benchmark::State& state) {
  nlobs::PicardEngine<3> e(paper_options());
  solve_loop(state, e);
}
void BM_Aitken(benchmark::State& state) {
  nlobs::AitkenEngine<3> e(paper_options());
  solve_loop(state, e);
}
void BM_Steffensen(benchmark::State& state) {
  nlobs::SteffensenEngine<3> e(paper_options());
  solve_loop(state, e);
}
void BM_Anderson(benchmark::State& state) {
  nlobs::AndersonEngine<3> e({.depth = static_cast<int>(state.range(0)), .damping = 1.0},
                             paper_options());
  solve_loop(state, e);
}
void BM_Newton(benchmark::State& state) {
  nlobs::NewtonEngine<3> e({.line_search = state.range(0) != 0}, paper_options());
  solve_loop(state, e);
}
BENCHMARK(BM_Picard);
BENCHMARK(BM_Aitken);
BENCHMARK(BM_Steffensen);
BENCHMARK(BM_Anderson)->Arg(2)->Arg(3);
BENCHMARK(BM_Newton)->Arg(0)->Arg(1);

void BM_Kinsol(benchmark::State& state) {
  const ChuaWindowCase& c = chua();
  const auto strategy = static_cast<KinsolStrategy>(state.range(0));
  const auto solver = nlobs::reference::make_kinsol_solver(
      c.problem, {.strategy = strategy, .tolerance = kTolerance, .anderson_depth = 2});
  Eigen::VectorXd x(3);
  nlobs::reference::KinsolResult r;
  for (auto _ : state) {
    x = c.initial_guess;
    r = solver->solve(x);
    benchmark::DoNotOptimize(x);
  }
  state.counters["iterations"] = static_cast<double>(r.iterations);
  state.counters["evaluations"] = static_cast<double>(r.evaluations);
  state.counters["converged"] = r.success;
  state.SetLabel(KinsolSolver::name(strategy));
}
BENCHMARK(BM_Kinsol)
    ->Arg(static_cast<int>(KinsolStrategy::kFixedPoint))
    ->Arg(static_cast<int>(KinsolStrategy::kFixedPointAnderson))
    ->Arg(static_cast<int>(KinsolStrategy::kNewtonLineSearch));

}  // namespace
