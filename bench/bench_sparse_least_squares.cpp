// Levenberg–Marquardt on a sparse least-squares problem with no zero residual
// (test::smoothed_fit, m = 2n − 1, two entries of J a row) at n = 10⁴ … 10⁶: nlobs' sparse path
// (the user's unchanged with_autodiff; J's pattern detected, the damped normal equations by
// CHOLMOD) against Ceres' own Levenberg–Marquardt driver with SPARSE_NORMAL_CHOLESKY (also
// CHOLMOD), written as a Ceres user writes it — one autodiff residual block per residual, one
// parameter block per unknown — and stopped by the same relative reduction, 1e-10. The counter
// `cost` is ½‖F‖₂² at the answer, so both are seen to reach the same minimum.
#include <benchmark/benchmark.h>
#include <ceres/ceres.h>

#include <vector>

#include "large_test_problems.hpp"
#include "nlobs/solvers/levenberg_marquardt_engine.hpp"

namespace {

using nlobs::Index;

void BM_SparseLevenbergMarquardtSmoothedFit(benchmark::State& state) {
  const Index n = state.range(0);
  const Eigen::VectorXd data = nlobs::test::smoothed_fit_data(n);
  nlobs::Summary s;
  Eigen::VectorXd x;
  for (auto _ : state) {
    x = Eigen::VectorXd::Zero(n);
    const auto problem =
        nlobs::RootProblem<>::with_autodiff(nlobs::test::smoothed_fit(data), n, 2 * n - 1);
    nlobs::SolverOptions options;
    options.stop.max_iterations = 200;
    nlobs::LevenbergMarquardtEngine<> lm({}, options);
    s = lm.solve_least_squares(problem, x);
    if (s.status != nlobs::Status::kConverged || s.linear_solver != "cholmod") {
      state.SkipWithError("not converged on the sparse path");
      return;
    }
    benchmark::DoNotOptimize(x.data());
  }
  Eigen::VectorXd f(2 * n - 1);
  nlobs::test::smoothed_fit(data)(x, f);
  state.counters["n"] = static_cast<double>(n);
  state.counters["steps"] = s.iterations;
  state.counters["factorisations"] = s.linear_setups;
  state.counters["cost"] = 0.5 * f.squaredNorm();
}
BENCHMARK(BM_SparseLevenbergMarquardtSmoothedFit)
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(1000000)
    ->Unit(benchmark::kMillisecond);

struct DataCost {
  double d;
  template <typename T>
  bool operator()(const T* xi, const T* next, T* r) const {
    r[0] = exp(xi[0]) + 0.1 * xi[0] * next[0] - d;
    return true;
  }
};
struct LastDataCost {
  double d;
  template <typename T>
  bool operator()(const T* xi, T* r) const {
    r[0] = exp(xi[0]) - d;
    return true;
  }
};
struct SmoothingCost {
  double alpha;
  template <typename T>
  bool operator()(const T* xi, const T* next, T* r) const {
    r[0] = alpha * (next[0] - xi[0]);
    return true;
  }
};

void BM_CeresSparseNormalCholeskySmoothedFit(benchmark::State& state) {
  const Index n = state.range(0);
  const Eigen::VectorXd data = nlobs::test::smoothed_fit_data(n);
  ceres::Solver::Summary summary;
  for (auto _ : state) {
    std::vector<double> x(static_cast<std::size_t>(n), 0.0);
    ceres::Problem problem;
    for (Index i = 0; i < n; ++i) {
      double* xi = &x[static_cast<std::size_t>(i)];
      if (i + 1 < n) {
        double* next = xi + 1;
        problem.AddResidualBlock(
            new ceres::AutoDiffCostFunction<DataCost, 1, 1, 1>(new DataCost{data[i]}), nullptr, xi,
            next);
        problem.AddResidualBlock(
            new ceres::AutoDiffCostFunction<SmoothingCost, 1, 1, 1>(new SmoothingCost{0.5}),
            nullptr, xi, next);
      } else {
        problem.AddResidualBlock(
            new ceres::AutoDiffCostFunction<LastDataCost, 1, 1>(new LastDataCost{data[i]}), nullptr,
            xi);
      }
    }
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    options.function_tolerance = 1e-10;
    options.max_num_iterations = 200;
    options.num_threads = 1;
    ceres::Solve(options, &problem, &summary);
    if (summary.termination_type != ceres::CONVERGENCE) {
      state.SkipWithError("Ceres did not converge");
      return;
    }
    benchmark::DoNotOptimize(x.data());
  }
  state.counters["n"] = static_cast<double>(n);
  state.counters["steps"] = static_cast<double>(summary.iterations.size() - 1);
  state.counters["cost"] = summary.final_cost;
}
BENCHMARK(BM_CeresSparseNormalCholeskySmoothedFit)
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(1000000)
    ->Unit(benchmark::kMillisecond);

}  // namespace
