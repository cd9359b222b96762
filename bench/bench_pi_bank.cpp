// One step of a PI bank ([FFMG19], example 5: the lunar lander's three stages) on samples —
// an RK4 interval of the bank's rate (sampled_data.hpp, interval_integrator.hpp) — cycling over
// the first 2 s of the paper's run. No counter: the bank's accuracy is the tests' and the
// scenario's (pi-lander).
#include <benchmark/benchmark.h>

#include "nlobs/models/discretization.hpp"
#include "nlobs/models/systems.hpp"
#include "nlobs/observers/core/simulation.hpp"
#include "nlobs/observers/pi/pi_bank.hpp"

namespace {

void BM_PiBankStepLander(benchmark::State& state) {
  using namespace nlobs;
  const double g = 1.63, sigma = 50.0, alpha = 200.0, h = 1e-3;
  static const Measurements data = simulate(
      Discretized<LunarLanderImmersed>(LunarLanderImmersed{}, h, Scheme::kRk4),
      Eigen::Vector4d(-700, 0, 1500, 1),
      {.steps = 2000, .sample_time = h, .input = [](long) { return Eigen::VectorXd::Ones(1); }});
  PiBank bank(1, 1);
  const auto y = bank.output(0), u = bank.input(0);
  const auto x2 = bank.add_pi("x2", {.measured = y, .gains = {6, 25}});
  const auto x3 = bank.add_signal(
      "x3", [=](const PiBank::Values& v) { return sigma * alpha * v[u] / (g - v[x2.rate]); });
  const auto f = bank.add_pi("f", {.measured = x3,
                                   .a = -1.0,
                                   .b = [=](const PiBank::Values& v) { return -sigma * v[u]; },
                                   .gains = {49, 700},
                                   .initial_estimates = Eigen::Vector2d::Zero()});
  PiBankObserver observer(bank,
                          {.name = "pi", .estimate = {y, x2.eta, x3, f.eta}, .sample_time = h});
  std::vector<Eigen::VectorXd> ys, us;  // columns as vectors once, outside the timed loop
  for (long k = 0; k < data.steps(); ++k) {
    ys.emplace_back(data.y.col(k));
    us.emplace_back(data.u.col(k));
  }
  long k = 0;
  for (auto _ : state) {
    if (k == data.steps()) {
      observer.reset();
      k = 0;
    }
    benchmark::DoNotOptimize(
        observer.step(k, data.t[k], ys[static_cast<size_t>(k)], us[static_cast<size_t>(k)]));
    ++k;
  }
}
BENCHMARK(BM_PiBankStepLander)->Unit(benchmark::kMicrosecond);

}  // namespace
