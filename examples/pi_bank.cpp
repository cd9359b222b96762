// A bank of model-free PI observers ([FFMG19], example 5): the lunar lander's velocity x2 = ẏ,
// its mass from ẋ2, and the unknown mass-loss term f from the mass — three stages, one bank.
#include "nlobs/observers/pi/pi_bank.hpp"

#include <cmath>
#include <cstdio>

#include "nlobs/models/discretization.hpp"
#include "nlobs/models/systems.hpp"
#include "nlobs/observers/core/simulation.hpp"
#include "nlobs/observers/pi/pi_bound.hpp"

int main() {
  using namespace nlobs;
  const double g = 1.63, sigma = 50.0, alpha = 200.0, h = 1e-3;

  // The plant, with f = exp(6 sin t) as a fourth state so that we can score f̂.
  const Discretized<LunarLanderImmersed> lander(LunarLanderImmersed{}, h, Scheme::kRk4);
  const Measurements data = simulate(
      lander, Eigen::Vector4d(-700, 0, 1500, 1),
      {.steps = 12000, .sample_time = h, .input = [](long) { return Eigen::VectorXd::Ones(1); }});

  PiBank bank(/*outputs=*/1, /*inputs=*/1);
  const auto y = bank.output(0), u = bank.input(0);
  const auto x2 = bank.add_pi("x2", {.measured = y, .gains = {6, 25}});  // η = ẏ
  const auto x3 = bank.add_signal("x3", [=](const PiBank::Values& v) {   // x2' = g − σαu/x3
    return sigma * alpha * v[u] / (g - v[x2.rate]);
  });
  const auto f = bank.add_pi("f", {.measured = x3,  // f = −ẋ3 − σu: a = −1, b = −σu
                                   .a = -1.0,
                                   .b = [=](const PiBank::Values& v) { return -sigma * v[u]; },
                                   .gains = {49, 700},
                                   .initial_estimates = Eigen::Vector2d::Zero()});
  PiBankObserver observer(
      bank, {.name = "pi:lander", .estimate = {y, x2.eta, x3, f.eta}, .sample_time = h});

  double worst = 0.0;
  for (long k = 0; k < data.steps(); ++k) {
    const ObserverStep& s = observer.step(k, data.t[k], data.y.col(k), data.u.col(k));
    if (static_cast<double>(k) * h >= 5.0)
      worst = std::max(worst, std::abs(s.estimate[3] - data.x(3, k)));
  }
  const PiBound bound = pi_ultimate_bound({49, 700}, 588.2);  // N = max |d/dt exp(6 sin t)|
  std::printf("max |f - f_hat| for 5 s <= t < 12 s: %.1f (f peaks at %.0f)\n", worst,
              std::exp(6.0));
  std::printf("the f channel alone, with an exact x3: |e| <= %.1f\n", bound.eta_error);
  for (const auto& w : bound.warnings) std::printf("warning: %s\n", w.c_str());
  return worst < 150.0 ? 0 : 1;
}
