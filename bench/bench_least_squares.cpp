// Ceres on small fixed-size problems: TinySolver vs a prepared ceres::Problem vs a Problem
// built per solve; NLopt on small bounded problems: one nlopt::opt kept vs rebuilt per solve.
#include <benchmark/benchmark.h>

#include "nlobs/registry/problem_sets/chua_window_set.hpp"
#include "nlobs/solvers/ceres_engine.hpp"
#include "nlobs/solvers/nlopt_engine.hpp"

namespace {

// The modified-Chua window of six outputs (m = 6, n = 3), solved in the least-squares sense.
struct LongWindow {
  Eigen::Vector3d truth{1.0, 2.1428, -0.1648};
  Eigen::Vector3d guess{1.5, 2.5, 0.3};
  std::unique_ptr<nlobs::OutputWindow<nlobs::Discretized<nlobs::ModifiedChua>>> window =
      nlobs::reference::ChuaWindowCase::filled_window(truth, 6);
  nlobs::RootProblem<3, nlobs::Dynamic> problem = nlobs::window_residual_problem(*window);
};

const LongWindow& window() {
  static const LongWindow w;
  return w;
}

nlobs::SolverOptions options() {
  nlobs::SolverOptions o;
  o.stop.step_tolerance = 1e-10;
  o.stop.residual_tolerance = 1e-10;
  return o;
}

void run(benchmark::State& state, nlobs::CeresEngine<3>& engine) {
  nlobs::Summary s;
  for (auto _ : state) {
    nlobs::Vector<3> x = window().guess;
    s = engine.solve(window().problem, x);
    benchmark::DoNotOptimize(x);
  }
  state.counters["iterations"] = s.iterations;
  state.counters["evaluations"] = s.function_evaluations;
  state.counters["converged"] = s.converged();
}

void BM_CeresTinySolver(benchmark::State& state) {
  nlobs::CeresEngine<3> engine({.backend = nlobs::CeresOptions::Backend::kTinySolver}, options());
  run(state, engine);
}
BENCHMARK(BM_CeresTinySolver);

void BM_CeresPreparedProblem(benchmark::State& state) {
  nlobs::CeresEngine<3> engine({.backend = nlobs::CeresOptions::Backend::kSolver}, options());
  run(state, engine);
}
BENCHMARK(BM_CeresPreparedProblem);

// What a naive wrapper pays: a new engine (a new ceres::Problem) for every solve.
void BM_CeresProblemPerSolve(benchmark::State& state) {
  nlobs::Summary s;
  for (auto _ : state) {
    nlobs::CeresEngine<3> engine({.backend = nlobs::CeresOptions::Backend::kSolver}, options());
    nlobs::Vector<3> x = window().guess;
    s = engine.solve(window().problem, x);
    benchmark::DoNotOptimize(x);
  }
  state.counters["converged"] = s.converged();
}
BENCHMARK(BM_CeresProblemPerSolve);

// A 3-D bounded quadratic with its minimum on the box, as the MVT observer's β problems.
const nlobs::ObjectiveProblem<3>& bounded_quadratic() {
  static const auto q = nlobs::ObjectiveProblem<3>::with_autodiff([](const auto& b) {
    return (b[0] - 1.4) * (b[0] - 1.4) + (b[1] - 0.3) * (b[1] - 0.3) + (b[2] + 0.2) * (b[2] + 0.2);
  });
  return q;
}

nlobs::NloptOptions box(const char* algorithm) {
  return {.algorithm = algorithm,
          .lower_bounds = Eigen::Vector3d::Zero(),
          .upper_bounds = Eigen::Vector3d::Ones()};
}

void BM_NloptKeptOpt(benchmark::State& state) {
  nlobs::NloptEngine<3> engine(box("LD_SLSQP"), options());
  for (auto _ : state) {
    nlobs::Vector<3> b(0.5, 0.5, 0.5);
    engine.minimize(bounded_quadratic(), b);
    benchmark::DoNotOptimize(b);
  }
}
BENCHMARK(BM_NloptKeptOpt);

void BM_NloptOptPerSolve(benchmark::State& state) {
  for (auto _ : state) {
    nlobs::NloptEngine<3> engine(box("LD_SLSQP"), options());
    nlobs::Vector<3> b(0.5, 0.5, 0.5);
    engine.minimize(bounded_quadratic(), b);
    benchmark::DoNotOptimize(b);
  }
}
BENCHMARK(BM_NloptOptPerSolve);

}  // namespace
