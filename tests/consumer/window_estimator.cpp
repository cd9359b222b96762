// A user's file with a window estimator, the Ceres engine and an engine by name from the
// registry: the product's central composition, compiled against the installed headers
// (scripts/compile-cost reports its time).
#include <cstdio>
#include <nlobs/models/modified_chua.hpp>
#include <nlobs/observers/core/simulation.hpp>
#include <nlobs/observers/window/window_estimator.hpp>
#include <nlobs/solvers/ceres_engine.hpp>
#include <nlobs/solvers/engine_registry.hpp>

int main() {
  using Chua = nlobs::Discretized<nlobs::ModifiedChua>;
  const Chua model = nlobs::paper_modified_chua();
  nlobs::SimulationOptions simulation;
  simulation.steps = 60;
  simulation.sample_time = 0.05;
  const nlobs::Measurements data =
      nlobs::simulate(model, Eigen::Vector3d(1.0, 2.1428, -0.1648), simulation);
  nlobs::SolverOptions solver;
  solver.stop.step_tolerance = 1e-12;
  solver.stop.residual_tolerance = 1e-12;
  const Eigen::Vector3d guess(0.5, 1.0, 0.0);
  nlobs::WindowEstimatorOptions options;
  options.initial_estimate = guess;
  std::vector<std::unique_ptr<nlobs::Observer>> observers;
  observers.push_back(std::make_unique<nlobs::WindowEstimator<Chua>>(
      model, options, std::make_unique<nlobs::CeresEngine<3>>(nlobs::CeresOptions{}, solver)));
  observers.push_back(nlobs::make_window_estimator(model, "newton", options, solver));
  const auto run = nlobs::run_observers(data, observers);
  int failures = 0;
  for (size_t i = 0; i < observers.size(); ++i) {
    const double error =
        (run.estimates[i].rightCols(50) - data.x.rightCols(50)).cwiseAbs().maxCoeff();
    std::printf("%s: max error over the last 50 samples %.2e\n", observers[i]->name().c_str(),
                error);
    if (!(error < 1e-6)) ++failures;
  }
  return failures == 0 ? 0 : 1;
}
