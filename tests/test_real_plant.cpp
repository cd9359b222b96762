// A plant nlobs does not ship, as a user brings one: an exothermic CSTR that ignites when its
// coolant is warmed and is put out again when the coolant is cooled. At ignition the reaction
// rate grows by two orders of magnitude in a few samples, so one explicit step per sample is
// unstable there (the plant itself overflows); sub-steps of the model's discretisation
// (DiscretizationOptions::substeps, the model spec's "substeps"), the adaptive scheme dopri5 or
// the implicit sdirk3 make it, and the EKF, the UKF and the MHE on it, hold.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "nlobs/models/discretization.hpp"
#include "nlobs/models/reaction_diffusion_chain.hpp"
#include "nlobs/observers/baselines/baselines.hpp"
#include "nlobs/observers/baselines/unscented_kalman_filter.hpp"
#include "nlobs/observers/core/simulation.hpp"
#include "nlobs/observers/mhe/mhe_estimator.hpp"
#include "nlobs/registry/json_reader.hpp"
#include "nlobs/registry/model_registry.hpp"
#include "nlobs/registry/register_model.hpp"
#include "nlobs/solvers/autodiff.hpp"

namespace nlobs {
namespace {

// x = (c, T): concentration [mol/L] and temperature [K]; u = T_c, the coolant's temperature [K];
// y = T. With r = k0 exp(−E/T) c (time in minutes):
//   c' = (q/V)(c_f − c) − r,
//   T' = (q/V)(T_f − T) + J r + a (T_c − T),
// the parameters of the exothermic CSTR as the process-control literature commonly takes them
// (q/V = 1, c_f = 1, T_f = 350, k0 = 7.2e10, E = 8750, J = −ΔH/(ρ c_p) = 209.2, a = UA/(V ρ c_p)
// = 2.092). At T_c = 300, (0.5, 350) is its unstable middle steady state (it drifts to 349 K by
// t = 2); at T_c = 308 it ignites (a peak of 437 K, settling toward 382 K).
struct CoolantCstr : ModelSizes<2, 1, 1> {
  double k0 = 7.2e10, activation = 8750.0, heat = 209.2, cooling = 2.092;

  template <typename T>
  State<T> vector_field(const State<T>& x, const Input& u, double) const {
    using std::exp;
    const T rate = k0 * exp(-activation / x[1]) * x[0];
    State<T> dx;
    dx[0] = (1.0 - x[0]) - rate;
    dx[1] = (350.0 - x[1]) + heat * rate + cooling * (u[0] - x[1]);
    return dx;
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return Output<T>(x[1]);
  }
};

constexpr double kSampleTime = 0.1;  // minutes
constexpr long kSamples = 100;

// T_c: 300 K, warmed to 308 K at t = 2 (ignition), cooled to 296 K at t = 6 (put out).
Eigen::VectorXd coolant(long k) {
  const double t = static_cast<double>(k) * kSampleTime;
  return Eigen::VectorXd::Constant(1, t < 2.0 ? 300.0 : (t < 6.0 ? 308.0 : 296.0));
}

Measurements simulate_plant(int substeps, double noise = 0.0) {
  const Discretized<CoolantCstr> plant(CoolantCstr{}, kSampleTime,
                                       {.scheme = Scheme::kRk4, .substeps = substeps});
  SimulationOptions o;
  o.steps = kSamples;
  o.noise_std = noise;
  o.seed = 11;
  o.input = coolant;
  return simulate(plant, Eigen::Vector2d(0.5, 350.0), o);
}

TEST(RealPlant, OneStepPerSampleOverflowsAtIgnitionAndSubstepsHold) {
  const Measurements one = simulate_plant(1);
  EXPECT_LT(one.steps(), kSamples);
  EXPECT_NE(one.stop_message.find("the true state is not finite"), std::string::npos)
      << one.stop_message;
  const Measurements ten = simulate_plant(10), fine = simulate_plant(200);
  ASSERT_EQ(ten.steps(), kSamples) << ten.stop_message;
  ASSERT_EQ(fine.steps(), kSamples) << fine.stop_message;
  EXPECT_GT(fine.x.row(1).maxCoeff(), 385.0);  // it ignites ...
  EXPECT_LT(fine.x(1, kSamples - 1), 325.0);   // ... and is put out
  // 10 RK4 steps per sample are within 0.2 K of 200 over the whole run (measured: 0.07 K).
  EXPECT_LT((ten.x - fine.x).row(1).cwiseAbs().maxCoeff(), 0.2);
}

// The EKF a user writes for it, Q and R from the noise: on the model with 10 sub-steps it
// tracks the ignition and the quench from the temperature alone (measured: RMS 0.0009 mol/L and
// 0.19 K after 20 samples); on one step per sample its prediction overflows at ignition, named,
// and it is tens of kelvin off from there (measured: 67 K RMS).
TEST(RealPlant, TheEkfTracksTheIgnitionWithSubsteps) {
  const double sigma = 0.5;  // K
  const Measurements data = simulate_plant(200, sigma);
  ASSERT_EQ(data.steps(), kSamples) << data.stop_message;
  const auto run = [&](int substeps) {
    EkfOptions o;
    o.initial_estimate = Eigen::Vector2d(0.6, 348.0);
    o.initial_covariance = Eigen::Vector2d(0.01, 4.0).asDiagonal();
    o.process_covariance = Eigen::Vector2d(1e-6, 1e-2).asDiagonal();
    o.measurement_covariance = Eigen::MatrixXd::Constant(1, 1, sigma * sigma);
    using Model = Discretized<CoolantCstr>;
    std::vector<std::unique_ptr<Observer>> observers;
    observers.push_back(std::make_unique<ExtendedKalmanFilter<Model>>(
        Model(CoolantCstr{}, kSampleTime, {.scheme = Scheme::kRk4, .substeps = substeps}), o));
    return run_observers(data, observers, 20);
  };
  const RunResult ten = run(10);
  const ObserverMetrics& m = ten.metrics[0];
  EXPECT_TRUE(m.failures.empty()) << m.first_failure;
  ASSERT_EQ(m.mse_after_window.size(), 2);
  EXPECT_LT(std::sqrt(m.mse_after_window[0]), 0.005);  // mol/L: never measured
  EXPECT_LT(std::sqrt(m.mse_after_window[1]), sigma);  // K: at the noise floor or below
  EXPECT_LT(m.max_error_after[1], 4.0 * sigma);

  const RunResult one = run(1);
  const ObserverMetrics& f = one.metrics[0];
  EXPECT_GT(f.failures.count("non_finite_estimate"), 0u) << f.first_failure;
  EXPECT_NE(f.first_failure.find("the predicted covariance P at sample"), std::string::npos)
      << f.first_failure;
  EXPECT_FALSE(std::sqrt(f.mse_after_window[1]) < 10.0) << f.mse_after_window.transpose();
}

// The order of each scheme through sub-steps, measured where the solution is known in closed
// form (the reactor's is not): x' = −x + sin t, whose error halving the sub-step divides by 2^p.
struct ForcedDecay : ModelSizes<1, 0, 1> {
  template <typename T>
  State<T> vector_field(const State<T>& x, const Input&, double t) const {
    return State<T>(-x[0] + std::sin(t));
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return x;
  }
};

TEST(RealPlant, SubstepsConvergeAtEachSchemesOrder) {
  const double h = 0.5, horizon = 5.0, x0 = 1.0;
  const double exact =
      (x0 + 0.5) * std::exp(-horizon) + 0.5 * (std::sin(horizon) - std::cos(horizon));
  for (const auto& [scheme, order] : {std::pair{Scheme::kEuler, 1.0}, {Scheme::kRk4, 4.0}}) {
    double previous = 0.0;
    for (const int substeps : {2, 4, 8, 16}) {
      const Discretized<ForcedDecay> model(ForcedDecay{}, h,
                                           {.scheme = scheme, .substeps = substeps});
      Eigen::Matrix<double, 1, 1> x(x0);
      for (long k = 0; k < 10; ++k) x = model.f(x, {}, k);
      const double error = std::abs(x[0] - exact);
      if (previous > 0.0) {
        const double measured = std::log2(previous / error);
        EXPECT_NEAR(measured, order, 0.15) << "substeps " << substeps;
      }
      previous = error;
    }
  }
}

// The EKF's and the MHE's Jacobian of the move is AD through every sub-step: it agrees with
// central differences of the sub-stepped map (evaluated in double) at the ignition's steepest
// point, so the AD scalar's path takes the same sub-steps as the double one.
TEST(RealPlant, TheJacobianOfTheMoveIsAdThroughTheSubsteps) {
  const Discretized<CoolantCstr> model(CoolantCstr{}, kSampleTime,
                                       {.scheme = Scheme::kRk4, .substeps = 10});
  const Eigen::Vector2d x(0.3, 370.0);
  const Eigen::VectorXd u = coolant(30);
  auto f = [&](const auto& v) {
    using T = typename std::decay_t<decltype(v)>::Scalar;
    return Eigen::Matrix<T, 2, 1>(
        model.f(Eigen::Matrix<T, 2, 1>(v), Eigen::Matrix<double, 1, 1>(u), 30));
  };
  Matrix<2, 2> ad;
  autodiff_jacobian<2, 2>(f, x, ad);
  for (int j = 0; j < 2; ++j) {
    const double d = 1e-6 * std::max(1.0, std::abs(x[j]));
    Eigen::Vector2d up = x, down = x;
    up[j] += d;
    down[j] -= d;
    const Eigen::Vector2d column = (f(up) - f(down)) / (2.0 * d);
    EXPECT_LT((ad.col(j) - column).norm(), 1e-6 * column.norm()) << j;
  }
}

TEST(RealPlant, SubstepsOutOfRangeAreRefusedByName) {
  for (const int bad :
       {0, -1, 1001, std::numeric_limits<int>::max(), std::numeric_limits<int>::min()}) {
    try {
      Discretized<CoolantCstr>(CoolantCstr{}, kSampleTime, {.substeps = bad});
      ADD_FAILURE() << bad << " accepted";
    } catch (const InvalidInput& e) {
      EXPECT_EQ(std::string(e.what()), "DiscretizationOptions::substeps = " + std::to_string(bad) +
                                           " is out of range [1, 1000]");
    }
  }
  // The flow's bound counts sub-steps: 1e9 of h / substeps, not of h (a bound in h would run
  // 2e9 steps here: the test would time out rather than fail).
  const Discretized<CoolantCstr> fine(CoolantCstr{}, kSampleTime, {.substeps = 1000});
  EXPECT_THROW(fine.flow(Eigen::Vector2d(0.5, 350.0), Eigen::VectorXd::Constant(1, 300.0), 0.0,
                         2e6 * kSampleTime),
               InvalidInput);
}

// Over an interval off the grid the flow takes ⌈dt / δ⌉ equal steps, δ = h / substeps: 2.5 h
// with 4 sub-steps is 10 steps, the same as 2.5 h on a grid of h / 4 (not ⌈2.5⌉ · 4 = 12).
TEST(RealPlant, TheFlowOffTheGridStepsByTheSubstep) {
  const Discretized<CoolantCstr> four(CoolantCstr{}, kSampleTime,
                                      {.scheme = Scheme::kRk4, .substeps = 4});
  const Discretized<CoolantCstr> quarter(CoolantCstr{}, kSampleTime / 4, Scheme::kRk4);
  const Eigen::Vector2d x(0.3, 370.0);
  const Eigen::Matrix<double, 1, 1> u(308.0);
  EXPECT_EQ(four.flow(x, u, 3.0, 2.5 * kSampleTime), quarter.flow(x, u, 3.0, 2.5 * kSampleTime));
  EXPECT_EQ(four.f(x, u, 30), quarter.flow(x, u, 3.0, kSampleTime));
}

// At n = 10^5 (the reaction–diffusion chain, run-time size): 4 sub-steps of a sample are the
// flow over it on a grid of h / 4, bit for bit, and the fronts stay finite and in [−0.5, 1.5].
TEST(RealPlant, SubstepsAtAHundredThousandStates) {
  const long n = 100000;
  const ReactionDiffusionChain chain({.cells = n, .sensors = 8});
  const Discretized<ReactionDiffusionChain> four(chain, 0.25,
                                                 {.scheme = Scheme::kRk4, .substeps = 4});
  const Discretized<ReactionDiffusionChain> quarter(chain, 0.0625, Scheme::kRk4);
  Eigen::VectorXd x(n);
  for (long i = 0; i < n; ++i) x[i] = i < n / 4 ? 1.0 : 0.0;  // a front at n / 4
  const ModelVector<double, 0> u;
  const Eigen::VectorXd stepped = four.f(x, u, 3);
  EXPECT_EQ(stepped, quarter.flow(x, u, 0.75, 0.25));
  EXPECT_TRUE(stepped.allFinite());
  EXPECT_GT(stepped.minCoeff(), -0.5);
  EXPECT_LT(stepped.maxCoeff(), 1.5);
  EXPECT_NE(stepped, x);
}

// From a scenario file: the model spec's "substeps" (the entry's default when absent) reaches
// the discretisation every observer and the simulated plant use; a bad value names the key.
TEST(RealPlant, TheModelSpecTakesSubsteps) {
  ModelRegistry registry("model");
  registry.add(model_entry(ModelDefinition<CoolantCstr>{.name = "cstr",
                                                        .description = "exothermic CSTR",
                                                        .default_step = kSampleTime,
                                                        .default_substeps = 10}));
  const auto instance = [&](const nlohmann::json& spec) {
    JsonReader reader(spec, "scenario.model");
    return make_model_instance(reader, registry);
  };
  const Eigen::Vector2d x(0.3, 370.0);
  const Eigen::VectorXd u = coolant(30);
  for (const auto& [spec, substeps] :
       {std::pair{nlohmann::json{{"name", "cstr"}}, 10},
        {nlohmann::json{{"name", "cstr"}, {"substeps", 1}}, 1},
        {nlohmann::json{{"name", "cstr"}, {"substeps", 1000}, {"scheme", "euler"}}, 1000}}) {
    const ModelInstance m = instance(spec);
    EXPECT_EQ(m.discretization.substeps, substeps) << spec;
    const Discretized<CoolantCstr> same(CoolantCstr{}, kSampleTime, m.discretization);
    EXPECT_EQ(m.discrete.f(Eigen::VectorXd(x), u, 30),
              same.f(x, Eigen::Matrix<double, 1, 1>(u), 30));
  }
  for (const nlohmann::json& bad :
       {nlohmann::json(0), nlohmann::json(1001), nlohmann::json(2.5), nlohmann::json("ten"),
        nlohmann::json(-3), nlohmann::json(1e300), nlohmann::json(true)}) {
    try {
      instance({{"name", "cstr"}, {"substeps", bad}});
      ADD_FAILURE() << bad << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("scenario.model: 'substeps'"), std::string::npos)
          << e.what();
    }
  }
  ModelEntry hand_built = model_entry(ModelDefinition<CoolantCstr>{.name = "cstr-2"});
  hand_built.default_substeps = 1001;
  try {
    registry.add(hand_built, "a test");
    ADD_FAILURE() << "an entry with default_substeps 1001 was added";
  } catch (const InvalidInput& e) {
    EXPECT_EQ(std::string(e.what()),
              "model 'cstr-2' from a test has default_substeps = 1001, out of range [1, 1000]");
  }
  try {
    model_entry(ModelDefinition<CoolantCstr>{.name = "cstr", .default_substeps = 0});
    ADD_FAILURE() << "default_substeps = 0 accepted";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("model 'cstr': default_substeps: "
                                         "DiscretizationOptions::substeps = 0 is out of range"),
              std::string::npos)
        << e.what();
  }
}

// The plant on one step per sample of each scheme against 200 RK4 steps: rk4 overflows at
// ignition (above); sdirk3 is stable through it but one third-order step of 0.1 min cannot
// follow a rise of 80 K in 0.3 min (measured: 6.7 K at worst, 1.5 K with 5 sub-steps); dopri5's
// error control finds the steps it needs (measured: 0.001 K).
TEST(RealPlant, TheAdaptiveAndImplicitSchemesHoldTheIgnitionAtOneStepPerSample) {
  const Measurements fine = simulate_plant(200);
  const auto worst = [&](Scheme scheme, int substeps) {
    const Discretized<CoolantCstr> plant(CoolantCstr{}, kSampleTime,
                                         {.scheme = scheme, .substeps = substeps});
    SimulationOptions o;
    o.steps = kSamples;
    o.input = coolant;
    const Measurements data = simulate(plant, Eigen::Vector2d(0.5, 350.0), o);
    EXPECT_EQ(data.steps(), kSamples) << scheme_name(scheme) << ": " << data.stop_message;
    return data.steps() == kSamples ? (data.x - fine.x).row(1).cwiseAbs().maxCoeff()
                                    : std::numeric_limits<double>::infinity();
  };
  EXPECT_LT(worst(Scheme::kSdirk3, 1), 10.0);
  EXPECT_LT(worst(Scheme::kSdirk3, 5), 2.0);
  EXPECT_LT(worst(Scheme::kDopri5, 1), 0.01);
}

// What a new user gets from the defaults: the model on dopri5 (one "sample" of error control,
// default tolerances), Q and R from the noise, and the EKF, the UKF and the MHE each track the
// ignition and the quench from the temperature alone, with no failure; the unmeasured
// concentration within 0.005 mol/L RMS after 20 samples, the temperature at the noise floor.
// The same on sdirk3 at one step per sample, whose model error (6.7 K at worst, above) the
// process noise must absorb: measured here, the looser bound says how much it costs.
TEST(RealPlant, TheEkfUkfAndMheTrackTheIgnitionOnTheAdaptiveAndImplicitSchemes) {
  const double sigma = 0.5;  // K
  const Measurements data = simulate_plant(200, sigma);
  ASSERT_EQ(data.steps(), kSamples) << data.stop_message;
  using Model = Discretized<CoolantCstr>;
  const Eigen::Vector2d guess(0.6, 348.0);
  const Eigen::Matrix2d p0 = Eigen::Vector2d(0.01, 4.0).asDiagonal();
  const Eigen::Matrix2d q = Eigen::Vector2d(1e-6, 1e-2).asDiagonal();
  const Eigen::MatrixXd r = Eigen::MatrixXd::Constant(1, 1, sigma * sigma);
  for (const auto& [scheme, kelvin] : {std::pair{Scheme::kDopri5, sigma}, {Scheme::kSdirk3, 3.0}}) {
    const Model model(CoolantCstr{}, kSampleTime, {.scheme = scheme});
    // The same prior and noise for each (EkfOptions, UkfOptions, MheOptions share the fields).
    const auto shared = [&](auto options) {
      options.initial_estimate = guess;
      options.initial_covariance = p0;
      options.process_covariance = q;
      options.measurement_covariance = r;
      return options;
    };
    std::vector<std::unique_ptr<Observer>> observers;
    observers.push_back(std::make_unique<ExtendedKalmanFilter<Model>>(model, shared(EkfOptions{})));
    observers.push_back(
        std::make_unique<UnscentedKalmanFilter<Model>>(model, shared(UkfOptions{})));
    observers.push_back(std::make_unique<MheEstimator<Model>>(model, shared(MheOptions{})));
    const RunResult result = run_observers(data, observers, 20);
    for (const ObserverMetrics& o : result.metrics) {
      SCOPED_TRACE(std::string(scheme_name(scheme)) + " " + o.name);
      EXPECT_TRUE(o.failures.empty()) << o.first_failure;
      ASSERT_EQ(o.mse_after_window.size(), 2);
      EXPECT_LT(std::sqrt(o.mse_after_window[0]), 0.005);  // mol/L: never measured
      EXPECT_LT(std::sqrt(o.mse_after_window[1]), kelvin);
    }
  }
}

}  // namespace
}  // namespace nlobs
