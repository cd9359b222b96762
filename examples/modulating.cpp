// The modulating-function observer ([MF-LTV]) on the LTI system with output injection
// y'' + 0.5 y' + y = sin y, from noisy samples (σ = 0.01, δ = 10 ms): the derivative y' one
// horizon after start, beside backward differences of the same samples.
#include <cmath>
#include <cstdio>

#include "nlobs/models/discretization.hpp"
#include "nlobs/models/systems.hpp"
#include "nlobs/observers/baselines/finite_difference_observer.hpp"
#include "nlobs/observers/core/simulation.hpp"
#include "nlobs/observers/modulating/modulating_function_observer.hpp"

int main() {
  using namespace nlobs;
  const double h = 0.01;
  const Discretized<LtiOutputInjection> plant(LtiOutputInjection{}, h, Scheme::kRk4);
  const Measurements data = simulate(plant, Eigen::Vector2d(2.0, 0.0),
                                     {.steps = 1001, .noise_std = 0.01, .sample_time = h});

  ModulatingOptions o;
  o.initial_estimate = Eigen::Vector2d::Zero();
  o.sample_time = h;
  o.horizon = 1.0;  // T = 100 samples: the first estimate at t = 1 s
  ModulatingFunctionObserver<LtiInjectionForm> mf(LtiInjectionForm{}, o);
  FiniteDifferenceObserver differences({.states = 2, .sample_time = h});

  double mf_sum = 0.0, fd_sum = 0.0;
  double counted = 0.0;
  for (long k = 0; k < data.steps(); ++k) {
    const ObserverStep& s = mf.step(k, data.t[k], data.y.col(k), data.u.col(k));
    const ObserverStep& d = differences.step(k, data.t[k], data.y.col(k), data.u.col(k));
    if (!s.ready) continue;
    mf_sum += std::pow(s.estimate[1] - data.x(1, k), 2);
    fd_sum += std::pow(d.estimate[1] - data.x(1, k), 2);
    counted += 1.0;
  }
  const double mf_rms = std::sqrt(mf_sum / counted), fd_rms = std::sqrt(fd_sum / counted);
  std::printf(
      "RMS error of y' after one horizon: modulating functions %.2e, finite differences "
      "%.2e (noise gains of eta_hat: %.3f, %.3f)\n",
      mf_rms, fd_rms, mf.noise_gains()[0], mf.noise_gains()[1]);
  return mf_rms < fd_rms / 5.0 ? 0 : 1;
}
