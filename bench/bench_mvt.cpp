// One step of the MVT observer ([BMH]) — a sample interval of RK4, four right-hand sides,
// each solving β — on the paper's two examples, per β solver. The steps cycle over the first
// 2 s of case 2 (chaotic) and of the robot with ê(0) ≠ x(0) − x̂(0), where ê is far from zero
// and every β problem is a real one (later ê decays and rows reach tolerance at once).
// Counter: the largest ‖X(β)‖ over the timed steps.
#include <benchmark/benchmark.h>

#include "nlobs/models/discretization.hpp"
#include "nlobs/models/systems.hpp"
#include "nlobs/observers/core/simulation.hpp"
#include "nlobs/observers/mvt/mvt_observer.hpp"

namespace {

using nlobs::MvtBetaMethod;

constexpr double kStep = 1e-3;
constexpr long kSamples = 2000;

template <typename Model>
struct Example {
  nlobs::Measurements data;
  Eigen::VectorXd xhat0, ehat0;
};

const Example<nlobs::ChaoticNoLinear>& chaotic() {
  static const Example<nlobs::ChaoticNoLinear> e = [] {
    nlobs::SimulationOptions o;
    o.steps = kSamples;
    o.sample_time = kStep;
    return Example<nlobs::ChaoticNoLinear>{
        nlobs::simulate(nlobs::Discretized<nlobs::ChaoticNoLinear>({}, kStep, nlobs::Scheme::kRk4),
                        Eigen::Vector3d(-2, -1, -1), o),
        Eigen::Vector3d(-1, -0.5, -1.5), Eigen::Vector3d(-1, -0.5, 0.2)};
  }();
  return e;
}

const Example<nlobs::FlexibleJointRobot>& robot() {
  static const Example<nlobs::FlexibleJointRobot> e = [] {
    nlobs::SimulationOptions o;
    o.steps = kSamples;
    o.sample_time = kStep;
    o.input = [](long k) {
      return Eigen::VectorXd::Constant(1, std::sin(static_cast<double>(k) * kStep));
    };
    return Example<nlobs::FlexibleJointRobot>{
        nlobs::simulate(
            nlobs::Discretized<nlobs::FlexibleJointRobot>({}, kStep, nlobs::Scheme::kRk4),
            Eigen::Vector4d(3, 3, 3, 3), o),
        Eigen::Vector4d(-1, -2, -0.5, -1), Eigen::Vector4d(4, 5, 3.5, 3)};
  }();
  return e;
}

template <typename Model>
void step(benchmark::State& state, const Example<Model>& example, MvtBetaMethod method,
          bool polish) {
  nlobs::MvtOptions o;
  o.sample_time = kStep;
  o.beta.method = method;
  o.beta.polish_rows = polish;
  o.initial_estimate = example.xhat0;
  o.initial_error_estimate = example.ehat0;
  nlobs::MvtObserver<Model> observer(Model{}, o);
  // Columns as vectors once, outside the timed loop.
  std::vector<Eigen::VectorXd> ys, us;
  for (long k = 0; k < kSamples; ++k) {
    ys.emplace_back(example.data.y.col(k));
    us.emplace_back(example.data.u.col(k));
  }
  long k = 0;
  double worst = 0.0;
  for (auto _ : state) {
    if (k == kSamples) {
      observer.reset();
      k = 0;
    }
    const nlobs::ObserverStep& s =
        observer.step(k, example.data.t[k], ys[static_cast<size_t>(k)], us[static_cast<size_t>(k)]);
    worst = std::max(worst, s.signals[0]);
    benchmark::DoNotOptimize(s.estimate.data());
    ++k;
  }
  state.counters["max_residual"] = worst;
}

void BM_MvtStepChaotic(benchmark::State& state) {
  step(state, chaotic(), static_cast<MvtBetaMethod>(state.range(0)), state.range(1) != 0);
}
void BM_MvtStepRobot(benchmark::State& state) {
  step(state, robot(), static_cast<MvtBetaMethod>(state.range(0)), state.range(1) != 0);
}

// Arguments: {method (0 per-row, 1 nlopt, 2 ceres), polish rows}.
void methods(benchmark::internal::Benchmark* b) {
  b->ArgNames({"method", "polish"});
  b->Args({0, 1})->Args({1, 1})->Args({1, 0})->Args({2, 1})->Args({2, 0});
}

BENCHMARK(BM_MvtStepChaotic)->Apply(methods);
BENCHMARK(BM_MvtStepRobot)->Apply(methods);

}  // namespace
