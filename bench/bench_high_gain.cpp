// The high-gain observer ([HG-EMB23]), whole runs over recorded data so that the cost per step
// and the accuracy come from the same steps:
//   BM_HighGainStep/<example>: µs per sample for each way of getting x̂ and α — the explicit
//     inverse, the least-squares projection with a hand map (ceres::Jet Jacobian), the Taylor
//     map (Boost autodiff) and the ADOL-C map, α explicit or L_f^N h;
//   BM_HighGainIntegrator/<rk4|cvode>/<θ·1000>: the oscillator at h = 0.01 as θ shrinks —
//     the measurement behind the `auto` choice (RK4 while h·max|p|/θ ≤ 0.2);
//   BM_ObservabilityMap/<call>/<map>: one call of q_N, ∂q_N/∂x or L_f^N h with its gradient,
//     hand expansion vs Taylor mode (Boost autodiff) vs ADOL-C, Duffing N = 6 and Lorenz N = 4.
// Counters: z_error = ‖q_N(x) − ẑ‖ at the last sample, failures.
#include <benchmark/benchmark.h>

#include "nlobs/models/discretization.hpp"
#include "nlobs/models/embedded_forms.hpp"
#include "nlobs/models/systems.hpp"
#include "nlobs/observers/core/simulation.hpp"
#include "nlobs/observers/high_gain/high_gain_observer.hpp"
#include "nlobs/observers/high_gain/lie_observability_map.hpp"
#include "nlobs/observers/high_gain/taylor_observability_map.hpp"

namespace {

using namespace nlobs;

template <typename Model>
Measurements record(const Model& model, const Eigen::VectorXd& x0, double h, double t_end) {
  SimulationOptions o;
  o.steps = std::lround(t_end / h) + 1;
  o.sample_time = h;
  return simulate(Discretized<Model>(model, h, Scheme::kRk4), x0, o);
}

template <typename Model>
void run(benchmark::State& state, const Measurements& data,
         const std::function<std::unique_ptr<HighGainObserver<Model>>()>& make) {
  double z_error = 0.0;
  long failures = 0, steps = 0;
  for (auto _ : state) {
    state.PauseTiming();
    auto observer = make();
    state.ResumeTiming();
    for (Eigen::Index k = 0; k < data.steps(); ++k) {
      failures +=
          observer->step(k, data.t[k], data.y.col(k), data.u.col(k)).failure.empty() ? 0 : 1;
    }
    steps += data.steps();
    const Eigen::Index last = data.steps() - 1;
    z_error = (observer->coordinates_at(data.x.col(last), data.t[last]) - observer->zhat()).norm();
  }
  state.counters["z_error"] = z_error;
  state.counters["failures"] = static_cast<double>(failures);
  state.counters["us_per_step"] = benchmark::Counter(
      static_cast<double>(steps) * 1e-6, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

SmoothSaturation oscillator_saturation() {
  return {Eigen::Vector4d(0.594, 0.421, 0.266, 0.153).asDiagonal(), 1.0, 2.0};
}

void BM_HighGainStepOscillator(benchmark::State& state) {
  static const Measurements data =
      record(OscillatorNonlinearOutput{}, Eigen::Vector2d(-0.5, 0.0), 0.01, 20.0);
  const bool inverse = state.range(0) == 1;
  run<OscillatorNonlinearOutput>(state, data, [inverse] {
    HighGainDesign d;
    d.map = std::make_shared<ExplicitObservabilityMap<OscillatorEmbedding>>();
    d.alpha = explicit_alpha<OscillatorEmbedding>();
    if (inverse) d.inverse = explicit_inverse<OscillatorEmbedding>();
    HighGainOptions o;
    o.sample_time = 0.01;
    o.theta = 0.3;
    o.saturation = oscillator_saturation();
    o.design = std::move(d);
    o.initial_estimate = Eigen::Vector2d(-0.3, 0.0);
    return std::make_unique<HighGainObserver<OscillatorNonlinearOutput>>(
        OscillatorNonlinearOutput{}, std::move(o));
  });
  state.SetLabel(inverse ? "explicit inverse" : "ceres projection, hand map");
}
BENCHMARK(BM_HighGainStepOscillator)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);

// Map 0: hand expansion, 1: ADOL-C, 2: Taylor mode.
void BM_HighGainStepDuffing(benchmark::State& state) {
  static const Measurements data = record(Duffing{}, Eigen::Vector2d(1.2, 0.0), 1e-3, 12.0);
  const long which = state.range(0);
  run<Duffing>(state, data, [which] {
    HighGainDesign d;
    if (which == 1) {
      d.map = std::make_shared<LieObservabilityMap>(Duffing{}, 6);
    } else if (which == 2) {
      d.map = std::make_shared<TaylorObservabilityMap<Duffing, 6>>();
    } else {
      d.map = std::make_shared<ExplicitObservabilityMap<DuffingEmbedding>>();
    }
    d.alpha = explicit_alpha<DuffingEmbedding>();
    HighGainOptions o;
    o.sample_time = 1e-3;
    o.theta = 0.1;
    Eigen::VectorXd P(6);
    P << 0.8, 0.145, 0.103, 0.0158, 4.07e-3, 5.26e-4;
    o.saturation = SmoothSaturation{P.asDiagonal(), 1.0, 2.0};
    o.design = std::move(d);
    o.initial_estimate = Eigen::Vector2d::Zero();
    return std::make_unique<HighGainObserver<Duffing>>(Duffing{}, std::move(o));
  });
  state.SetLabel(which == 1   ? "ceres projection, ADOL-C map"
                 : which == 2 ? "ceres projection, Taylor map"
                              : "ceres projection, hand map");
}
BENCHMARK(BM_HighGainStepDuffing)
    ->Arg(0)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

// Map 1: ADOL-C, 2: Taylor mode.
void BM_HighGainStepLorenzLieAlpha(benchmark::State& state) {
  static const Measurements data = record(Lorenz{}, Eigen::Vector3d(1.0, 1.0, 20.0), 1e-3, 5.0);
  const bool taylor = state.range(0) == 2;
  run<Lorenz>(state, data, [taylor] {
    HighGainDesign d;
    if (taylor) {
      d.map = std::make_shared<TaylorObservabilityMap<Lorenz, 4>>();
    } else {
      d.map = std::make_shared<LieObservabilityMap>(Lorenz{}, 4);
    }
    HighGainOptions o;
    o.sample_time = 1e-3;
    o.theta = 0.02;
    o.design = std::move(d);
    o.initial_estimate = Eigen::Vector3d(2, 3, 25);
    return std::make_unique<HighGainObserver<Lorenz>>(Lorenz{}, std::move(o));
  });
  state.SetLabel(taylor ? "alpha = L_f^4 h by Taylor mode, ceres projection"
                        : "alpha = L_f^4 h by ADOL-C, ceres projection");
}
BENCHMARK(BM_HighGainStepLorenzLieAlpha)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

void BM_HighGainIntegrator(benchmark::State& state) {
  static const Measurements data =
      record(OscillatorNonlinearOutput{}, Eigen::Vector2d(-0.5, 0.0), 0.01, 20.0);
  const bool cvode = state.range(0) == 1;
  const double theta = static_cast<double>(state.range(1)) / 1000.0;
  run<OscillatorNonlinearOutput>(state, data, [cvode, theta] {
    HighGainDesign d;
    d.map = std::make_shared<ExplicitObservabilityMap<OscillatorEmbedding>>();
    d.alpha = explicit_alpha<OscillatorEmbedding>();
    d.inverse = explicit_inverse<OscillatorEmbedding>();
    HighGainOptions o;
    o.sample_time = 0.01;
    o.theta = theta;
    o.saturation = oscillator_saturation();
    o.integrator = cvode ? HighGainIntegrator::kCvode : HighGainIntegrator::kRk4;
    o.design = std::move(d);
    o.initial_estimate = Eigen::Vector2d(-0.3, 0.0);
    return std::make_unique<HighGainObserver<OscillatorNonlinearOutput>>(
        OscillatorNonlinearOutput{}, std::move(o));
  });
  state.SetLabel(std::string(cvode ? "cvode" : "rk4") +
                 ", h*|p|/theta = " + std::to_string(0.01 / theta));
}
BENCHMARK(BM_HighGainIntegrator)
    ->ArgsProduct({{0, 1}, {300, 100, 30, 10, 5, 3}})
    ->Unit(benchmark::kMillisecond);

// One map call: range(0) = 0 value, 1 Jacobian, 2 L_f^N h with its gradient; range(1) = the map
// as above (0 hand, 1 ADOL-C, 2 Taylor).
template <typename Model, typename Form>
void map_calls(benchmark::State& state, const Eigen::VectorXd& x0) {
  constexpr int N = Form::kDimension;
  std::shared_ptr<ObservabilityMap> map;
  if (state.range(1) == 1) {
    map = std::make_shared<LieObservabilityMap>(Model{}, N);
  } else if (state.range(1) == 2) {
    map = std::make_shared<TaylorObservabilityMap<Model, N>>();
  } else {
    map = std::make_shared<ExplicitObservabilityMap<Form>>();
  }
  const long call = state.range(0);
  if (call == 2 && !map->has_next()) {
    state.SkipWithError("the hand map has no L_f^N h");
    return;
  }
  Eigen::VectorXd x = x0, z(N), gradient(x0.size());
  Eigen::MatrixXd dq(N, x0.size());
  double next = 0.0;
  for (auto _ : state) {
    x[0] += 1e-9;  // not a constant the compiler could fold
    const bool ok = call == 0   ? map->value(x, z)
                    : call == 1 ? map->jacobian(x, dq)
                                : map->next(x, next, &gradient);
    benchmark::DoNotOptimize(ok);
    benchmark::DoNotOptimize(z.data());
    benchmark::DoNotOptimize(dq.data());
    benchmark::DoNotOptimize(next);
  }
  static const char* calls[] = {"q_N", "dq_N/dx", "L_f^N h + gradient"};
  static const char* maps[] = {"hand", "ADOL-C", "Taylor"};
  state.SetLabel(std::string(calls[call]) + ", " + maps[state.range(1)]);
}

void BM_ObservabilityMapDuffing6(benchmark::State& state) {
  map_calls<Duffing, DuffingEmbedding>(state, Eigen::Vector2d(1.3, -0.7));
}
BENCHMARK(BM_ObservabilityMapDuffing6)
    ->ArgsProduct({{0, 1}, {0, 1, 2}})
    ->Args({2, 1})
    ->Args({2, 2})
    ->Unit(benchmark::kMicrosecond);

void BM_ObservabilityMapLorenz4(benchmark::State& state) {
  map_calls<Lorenz, LorenzEmbedding>(state, Eigen::Vector3d(1.3, -0.7, 20.0));
}
BENCHMARK(BM_ObservabilityMapLorenz4)
    ->ArgsProduct({{0, 1}, {0, 1, 2}})
    ->Args({2, 1})
    ->Args({2, 2})
    ->Unit(benchmark::kMicrosecond);

}  // namespace
