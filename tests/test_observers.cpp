// Observer layer: output window, window estimators, baselines, harness (models: test_models.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "nlobs/models/modified_chua.hpp"
#include "nlobs/models/systems.hpp"
#include "nlobs/observers/baselines/baselines.hpp"
#include "nlobs/observers/core/any_model.hpp"
#include "nlobs/observers/core/simulation.hpp"
#include "nlobs/observers/window/window_estimator.hpp"
#include "nlobs/solvers/engine_registry.hpp"
#include "nlobs/solvers/newton_engine.hpp"
#include "test_support.hpp"

namespace nlobs {
namespace {

using Chua = Discretized<ModifiedChua>;
const Eigen::Vector3d kTrue(1.0, 2.1428, -0.1648);
const Eigen::Vector3d kGuess(5.0, 10.0, -5.0);

Measurements chua_data(long steps, double noise = 0.0) {
  SimulationOptions o;
  o.steps = steps;
  o.noise_std = noise;
  o.sample_time = 0.05;
  return simulate(paper_modified_chua(), kTrue, o);
}

// A linear discrete model x⁺ = A x + B u, y = C x, for baselines with known behaviour.
struct Linear2 : ModelSizes<2, 1, 1> {
  Eigen::Matrix2d a{{0.9, 0.2}, {-0.1, 0.8}};
  Eigen::Vector2d b{0.0, 1.0};
  template <typename T>
  State<T> f(const State<T>& x, const Input& u, long) const {
    return a.cast<T>() * x + (b * u[0]).cast<T>();
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return Output<T>(x[0]);
  }
};

TEST(OutputWindow, RingBufferAndMap) {
  OutputWindow<Chua> w(paper_modified_chua(), 4);
  EXPECT_THROW(OutputWindow<Chua>(paper_modified_chua(), 2), InvalidInput);  // N·p < n
  const Measurements m = chua_data(10);
  for (long k = 0; k < 7; ++k) w.push(k, m.y.col(k), Eigen::VectorXd(0));
  EXPECT_TRUE(w.full());
  EXPECT_EQ(w.first_index(), 3);
  for (int j = 0; j < 4; ++j) EXPECT_EQ(w.outputs()[j], m.y(0, 3 + j));  // oldest first
  // H of the true state at the window's first sample reproduces Y.
  const Eigen::Vector3d x3 = m.x.col(3);
  EXPECT_LT((w.map(x3) - w.outputs()).lpNorm<Eigen::Infinity>(), 1e-14);
  EXPECT_LT((w.propagate(x3, 3) - m.x.col(6)).lpNorm<Eigen::Infinity>(), 1e-14);
  EXPECT_THROW(w.push(9, m.y.col(9), Eigen::VectorXd(0)), InvalidInput);  // not consecutive
  EXPECT_THROW(w.push(7, Eigen::VectorXd::Constant(1, NAN), Eigen::VectorXd(0)), InvalidInput);
  EXPECT_THROW(w.push(7, Eigen::VectorXd::Zero(2), Eigen::VectorXd(0)), InvalidInput);
}

std::unique_ptr<Observer> window_estimator(const std::string& spec, double tol, long window = 0,
                                           WarmStart warm = WarmStart::kPropagated) {
  SolverOptions o;
  o.stop.step_tolerance = tol;
  o.stop.residual_tolerance = tol;
  WindowEstimatorOptions options;
  options.initial_estimate = kGuess;
  options.window = window;
  options.warm_start = warm;
  return make_window_estimator(paper_modified_chua(), spec, options, o);
}

TEST(WindowEstimator, NoiseFreeRecoveryByEveryEngine) {
  const Measurements data = chua_data(120);
  std::vector<std::unique_ptr<Observer>> observers;
  for (const char* e :
       {"picard", "aitken", "steffensen", "anderson", "newton", "ceres", "nlopt:LD_SLSQP"}) {
    observers.push_back(window_estimator(e, 1e-10));
  }
  observers.push_back(window_estimator("ceres", 1e-10, 6));
  auto result = run_observers(data, observers);
  for (size_t i = 0; i < observers.size(); ++i) {
    const long from = observers[i]->info().window - 1;
    const Eigen::MatrixXd err = (result.estimates[i] - data.x).rightCols(data.steps() - from);
    EXPECT_LT(err.cwiseAbs().maxCoeff(), 1e-6) << observers[i]->name();
  }
}

TEST(WindowEstimator, NotReadyThenCoastsThenSolves) {
  auto est = window_estimator("newton", 1e-10);
  const Measurements data = chua_data(5);
  const Chua model = paper_modified_chua();
  Eigen::Vector3d coast = kGuess;
  for (long k = 0; k < 3; ++k) {
    const ObserverStep& s = est->step(k, data.t[k], data.y.col(k), Eigen::VectorXd(0));
    if (k < 2) {
      EXPECT_FALSE(s.ready);
      EXPECT_FALSE(s.summary.has_value());
      EXPECT_LT((s.estimate - coast).norm(), 1e-15);  // the initial guess carried through f
      coast = model.f(coast, {}, k);
    } else {
      EXPECT_TRUE(s.ready);
      ASSERT_TRUE(s.summary.has_value());
      EXPECT_TRUE(s.summary->converged());
      EXPECT_LT((s.estimate - data.x.col(2)).norm(), 1e-8);
    }
  }
}

TEST(WindowEstimator, MissingMeasurementSkipsAndRecovers) {
  Measurements data = chua_data(30);
  data.y(0, 10) = NAN;
  std::vector<std::unique_ptr<Observer>> observers;
  observers.push_back(window_estimator("steffensen", 1e-10));
  const auto r = run_observers(data, observers);
  EXPECT_EQ(r.metrics[0].failures.at("missing_measurement"), 1);
  // Three samples after the gap (11, 12, 13) the window is full again and exact.
  EXPECT_LT((r.estimates[0].col(13) - data.x.col(13)).norm(), 1e-8);
  EXPECT_LT((r.estimates[0].col(29) - data.x.col(29)).norm(), 1e-8);
  EXPECT_TRUE(r.estimates[0].allFinite());
}

TEST(WindowEstimator, SquareEnginesRefuseLongWindows) {
  WindowEstimatorOptions options;
  options.initial_estimate = kGuess;
  options.window = 6;
  try {
    make_window_estimator(paper_modified_chua(), "picard", options);
    FAIL();
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("use ceres or nlopt"), std::string::npos) << e.what();
  }
  options.window = 0;
  options.initial_estimate = Eigen::Vector3d(NAN, 0, 0);
  EXPECT_THROW(make_window_estimator(paper_modified_chua(), "newton", options), InvalidInput);
}

TEST(WindowEstimator, PropagatedWarmStartNeedsFewerIterations) {
  const Measurements data = chua_data(200);
  std::vector<std::unique_ptr<Observer>> observers;
  observers.push_back(window_estimator("picard", 1e-5, 0, WarmStart::kPrevious));
  observers.push_back(window_estimator("picard", 1e-5, 0, WarmStart::kPropagated));
  const auto r = run_observers(data, observers);
  EXPECT_LT(r.metrics[1].iterations_mean * 10, r.metrics[0].iterations_mean);
}

// Every sample carries its time: measurements without one per sample are refused by name, not
// run on a made-up time axis.
TEST(RunObservers, MeasurementsWithoutTimesAreRefused) {
  Measurements data = chua_data(20);
  data.t.resize(19);
  std::vector<std::unique_ptr<Observer>> observers;
  observers.push_back(window_estimator("newton", 1e-10));
  EXPECT_EQ(test::message_of([&] { run_observers(data, observers); }),
            "run_observers: Measurements::t has 19 times for 20 samples; every sample needs its "
            "time");
}

TEST(WindowEstimator, LongWindowAttenuatesNoiseInX3) {
  // With N = n = 3 noise is amplified ~37× in x3 (our working notes on [MGFF23]); least
  // squares on N = 6 (ours) cures it.
  const Measurements data = chua_data(400, 0.01);
  std::vector<std::unique_ptr<Observer>> observers;
  observers.push_back(window_estimator("newton", 1e-10));
  observers.push_back(window_estimator("ceres", 1e-10, 6));
  const auto r = run_observers(data, observers);
  EXPECT_LT(10 * r.metrics[1].mse_after_window[2], r.metrics[0].mse_after_window[2]);
}

TEST(WindowEstimator, MultiOutputWindowByLeastSquares) {
  // Chaotic system without linear term: p = 2 outputs, n = 3 states. N = 2 samples give
  // 4 equations for 3 unknowns: the least-squares path, which recovers the state exactly.
  using Chaotic = Discretized<ChaoticNoLinear>;
  const Chaotic model(ChaoticNoLinear{}, 0.01, Scheme::kRk4);
  SimulationOptions o;
  o.steps = 50;
  o.sample_time = 0.01;
  const Measurements data = simulate(model, Eigen::Vector3d(-2.0, -1.0, -1.0), o);
  SolverOptions so;
  so.stop.step_tolerance = 1e-12;
  so.stop.residual_tolerance = 1e-12;
  std::vector<std::unique_ptr<Observer>> observers;
  WindowEstimatorOptions options;
  options.initial_estimate = Eigen::Vector3d(-1.0, -0.5, -1.5);
  observers.push_back(make_window_estimator(model, "ceres", options, so));
  EXPECT_EQ(observers[0]->info().window, 2);
  const auto r = run_observers(data, observers);
  EXPECT_LT((r.estimates[0].rightCols(49) - data.x.rightCols(49)).cwiseAbs().maxCoeff(), 1e-8);
}

// p = n: each sample determines the state alone (N = 1), so x̂[k] = w* with no propagation.
struct FullOutput : ModelSizes<2, 0, 2> {
  Duffing d;
  template <typename T>
  State<T> f(const State<T>& x, const Input&, long) const {
    return x + 0.01 * d.vector_field(x, Input(), 0.0);
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return Output<T>(x[0] + 0.1 * x[1] * x[1], x[1]);
  }
};

TEST(WindowEstimator, OneSampleWindowWhenTheOutputIsTheState) {
  SimulationOptions o;
  o.steps = 20;
  const FullOutput model;
  const Measurements data = simulate(model, Eigen::Vector2d(0.5, 0.2), o);
  std::vector<std::unique_ptr<Observer>> observers;
  WindowEstimatorOptions options;
  options.initial_estimate = Eigen::Vector2d(0.0, 0.0);
  observers.push_back(make_window_estimator(model, "newton:tol=1e-13", options));
  EXPECT_EQ(observers[0]->info().window, 1);
  const auto r = run_observers(data, observers);
  EXPECT_LT((r.estimates[0] - data.x).cwiseAbs().maxCoeff(), 1e-12);
}

// FullOutput with a sensor that fails while `broken`: h throws.
struct FailingSensor : FullOutput {
  static inline bool broken = false;
  template <typename T>
  Output<T> h(const State<T>& x) const {
    if (broken) throw std::runtime_error("sensor failed");
    return FullOutput::h(x);
  }
};

// Newton that notes, at every solve, whether it was asked to record its trace.
class TraceSpy : public Engine<2> {
 public:
  TraceSpy() : Engine<2>(SolverOptions{}) {}
  std::string_view name() const override { return "trace-spy"; }
  Summary solve(const FixedPointProblem<2>& problem, Vector<2>& x) override {
    asked.push_back(options().record_trace);
    return newton_.solve(problem, x);
  }
  std::vector<bool> asked;

 private:
  void on_set_record_trace(bool on) override { newton_.set_record_trace(on); }
  NewtonEngine<2> newton_;
};

// trace_first_window: the engine of every step records its trace on the first window after each
// reset only, and keeps its own setting otherwise — after a solve that threw too.
TEST(WindowEstimator, TracesTheFirstWindowAfterEachResetOnly) {
  SimulationOptions o;
  o.steps = 6;
  o.noise_std = 1e-3;  // every window a solve of its own (no guess already exact)
  const Measurements data = simulate(FullOutput{}, Eigen::Vector2d(0.5, 0.2), o);
  WindowEstimatorOptions options;
  options.initial_estimate = Eigen::Vector2d(0.0, 0.0);
  options.trace_first_window = true;
  auto owned = std::make_unique<TraceSpy>();
  TraceSpy* spy = owned.get();
  WindowEstimator<FailingSensor> estimator(FailingSensor{}, options, std::move(owned));
  const auto run = [&] {
    std::vector<std::size_t> sizes;
    for (long k = 0; k < data.steps(); ++k) {
      const ObserverStep& step = estimator.step(k, data.t[k], data.y.col(k), data.u.col(k));
      EXPECT_TRUE(step.summary.has_value()) << k;  // a one-sample window: solved every step
      if (step.summary) sizes.push_back(step.summary->trace.size());
    }
    return sizes;
  };
  for (int pass = 0; pass < 2; ++pass) {  // the second after a reset
    spy->asked.clear();
    const std::vector<std::size_t> sizes = run();
    EXPECT_EQ(spy->asked, std::vector<bool>({true, false, false, false, false, false})) << pass;
    ASSERT_EQ(sizes.size(), 6u);
    EXPECT_GT(sizes[0], 0u) << pass;
    for (std::size_t k = 1; k < sizes.size(); ++k) EXPECT_EQ(sizes[k], 0u) << pass << ' ' << k;
    EXPECT_FALSE(spy->options().record_trace);
    estimator.reset();
  }
  FailingSensor::broken = true;
  EXPECT_THROW(estimator.step(0, data.t[0], data.y.col(0), data.u.col(0)), std::runtime_error);
  FailingSensor::broken = false;
  EXPECT_FALSE(spy->options().record_trace) << "the failed first window left tracing on";
  // An engine that records every solve's trace keeps doing so.
  spy->set_record_trace(true);
  estimator.reset();
  spy->asked.clear();
  run();
  EXPECT_EQ(spy->asked, std::vector<bool>(6, true));
}

TEST(Baselines, LuenbergerErrorFollowsALC) {
  // Linear model: e⁺ = (A − L C) e exactly.
  const Linear2 model;
  const Eigen::Vector2d gain(0.5, 0.3);
  const Eigen::Vector2d x0(1.0, -1.0), guess(0.0, 0.0);
  LuenbergerOptions options;
  options.initial_estimate = guess;
  options.gain = gain;
  LuenbergerObserver<Linear2> obs(model, options);
  Eigen::Matrix2d alc = model.a;
  alc.col(0) -= gain;
  Eigen::Vector2d x = x0, e = x0 - guess;
  for (long k = 0; k < 20; ++k) {
    const Eigen::VectorXd u = Eigen::VectorXd::Constant(1, std::sin(0.3 * static_cast<double>(k)));
    const ObserverStep& s = obs.step(k, static_cast<double>(k), model.h(x), u);
    EXPECT_LT((x - s.estimate - e).norm(), 1e-12) << k;
    e = alc * e;
    x = model.f(x, Linear2::Input(u), k);
  }
  options.gain = Eigen::Vector3d::Ones();
  EXPECT_THROW(LuenbergerObserver<Linear2>(model, options), InvalidInput);
}

TEST(Baselines, EkfOnALinearSystemIsTheKalmanFilter) {
  // Noise-free linear system: the EKF converges to the state; with an exact initial state it
  // stays exact.
  const Linear2 model;
  EkfOptions options;
  options.initial_estimate = Eigen::Vector2d(0.0, 0.0);
  options.process_covariance = Eigen::Matrix2d::Identity() * 1e-8;
  options.measurement_covariance = Eigen::MatrixXd::Constant(1, 1, 1e-6);
  options.initial_covariance = Eigen::Matrix2d::Identity();
  ExtendedKalmanFilter<Linear2> ekf(model, options);
  Eigen::Vector2d x(1.0, -1.0);
  double last = 0.0;
  for (long k = 0; k < 60; ++k) {
    const Eigen::VectorXd u = Eigen::VectorXd::Constant(1, 0.1);
    last = (ekf.step(k, static_cast<double>(k), model.h(x), u).estimate - x).norm();
    x = model.f(x, Linear2::Input(u), k);
  }
  EXPECT_LT(last, 1e-6);
  options.process_covariance = -Eigen::Matrix2d::Identity();
  EXPECT_THROW(ExtendedKalmanFilter<Linear2>(model, options), InvalidInput);
}

TEST(Baselines, SlidingModeSaturates) {
  const Linear2 model;
  const Eigen::Vector2d q(0.0, 0.0), r(1.0, 0.0);
  SlidingModeOptions options;
  options.initial_estimate = Eigen::Vector2d(0.0, 0.0);
  options.q = q;
  options.r = r;
  options.gamma = 0.5;
  SlidingModeObserver<Linear2> smo(model, options);
  // y − ŷ = 10 ≫ γ: the correction is R · sat(20) = R.
  smo.step(0, 0.0, Eigen::VectorXd::Constant(1, 10.0), Eigen::VectorXd::Zero(1));
  const ObserverStep& s =
      smo.step(1, 1.0, Eigen::VectorXd::Constant(1, 0.0), Eigen::VectorXd::Zero(1));
  EXPECT_NEAR(s.estimate[0], 1.0, 1e-15);
  options.gamma = 0.0;
  EXPECT_THROW(SlidingModeObserver<Linear2>(model, options), InvalidInput);
}

// Names in reports: the registry's spec, the engine's own name, or the options' name.
TEST(WindowEstimator, TakesItsLabelFromTheEngine) {
  WindowEstimatorOptions options;
  options.initial_estimate = kGuess;
  EXPECT_EQ(make_window_estimator(paper_modified_chua(), "newton:tol=1e-10", options)->name(),
            "window:newton:tol=1e-10");
  EXPECT_EQ(make_window_estimator(paper_modified_chua(), "newton", options)->info().engine,
            "newton");
  WindowEstimator<Chua> direct(paper_modified_chua(), options,
                               std::make_unique<NewtonEngine<3>>(NewtonOptions{}));
  EXPECT_EQ(direct.name(), "window:newton");
  options.window = 6;
  EXPECT_EQ(make_window_estimator(paper_modified_chua(), "ceres", options)->name(),
            "window:ceres,N=6");
  options.name = "my estimator";
  EXPECT_EQ(make_window_estimator(paper_modified_chua(), "ceres", options)->name(), "my estimator");
  EXPECT_THROW(WindowEstimator<Chua>(paper_modified_chua(), options, nullptr), InvalidInput);
  EXPECT_THROW(make_window_estimator(paper_modified_chua(), "no-such-engine", options),
               InvalidInput);
}

// Each options struct names the field it refuses.
std::string refusal(const std::function<void()>& build) {
  try {
    build();
  } catch (const InvalidInput& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(ObserverOptions, ValidateNamesTheField) {
  const Linear2 model;
  WindowEstimatorOptions window;  // no initial estimate
  EXPECT_NE(refusal([&] {
              make_window_estimator(model, "newton", window);
            }).find("WindowEstimatorOptions::initial_estimate"),
            std::string::npos);
  window.initial_estimate = Eigen::Vector3d::Zero();  // 3 entries for 2 states
  EXPECT_NE(refusal([&] { make_window_estimator(model, "newton", window); }).find("has 3 entries"),
            std::string::npos);
  window.initial_estimate = Eigen::Vector2d::Zero();
  window.window = -1;
  EXPECT_NE(refusal([&] { window.validate(); }).find("WindowEstimatorOptions::window = -1"),
            std::string::npos);

  LuenbergerOptions luenberger;
  luenberger.initial_estimate = Eigen::Vector2d::Zero();
  EXPECT_NE(refusal([&] {
              LuenbergerObserver<Linear2>(model, luenberger);
            }).find("LuenbergerOptions::gain must be given"),
            std::string::npos);
  luenberger.gain = Eigen::Vector2d(NAN, 0.0);
  EXPECT_NE(refusal([&] { luenberger.validate(); }).find("every entry finite"), std::string::npos);
  luenberger.gain = Eigen::Vector2d(0.5, 0.3);
  luenberger.name.clear();
  EXPECT_NE(refusal([&] { luenberger.validate(); }).find("LuenbergerOptions::name"),
            std::string::npos);

  SlidingModeOptions sliding;
  sliding.initial_estimate = Eigen::Vector2d::Zero();
  sliding.q = sliding.r = Eigen::Vector2d(0.1, 0.1);
  sliding.gamma = -2.0;
  EXPECT_NE(refusal([&] {
              SlidingModeObserver<Linear2>(model, sliding);
            }).find("SlidingModeOptions::gamma must be finite and > 0 (got -2)"),
            std::string::npos);
  sliding.gamma = 0.5;
  sliding.q = Eigen::Vector3d::Zero();  // n × p = 2 × 1 wanted
  EXPECT_NE(refusal([&] { SlidingModeObserver<Linear2>(model, sliding); }).find("q must be"),
            std::string::npos);

  EkfOptions ekf;
  ekf.initial_estimate = Eigen::Vector2d::Zero();
  ekf.measurement_covariance = Eigen::MatrixXd::Constant(1, 2, 1.0);  // not square
  EXPECT_NE(refusal([&] {
              ekf.validate();
            }).find("EkfOptions::measurement_covariance must be square (got 1x2)"),
            std::string::npos);
  ekf.measurement_covariance = Eigen::Matrix2d{{1.0, 2.0}, {2.0, 1.0}};  // eigenvalues 3, −1
  EXPECT_NE(refusal([&] { ekf.validate(); }).find("must be positive semi-definite"),
            std::string::npos);
  ekf.measurement_covariance = Eigen::Matrix2d{{1.0, 1.0}, {1.0, 1.0}};  // eigenvalues 2, 0
  EXPECT_EQ(refusal([&] { ekf.validate(); }), "(accepted)");  // Cholesky fails; LDLT accepts
  ekf.measurement_covariance = Eigen::Vector3d(1.0, -1e-9, 2.0).asDiagonal();
  EXPECT_NE(refusal([&] { ekf.validate(); }).find("must be positive semi-definite"),
            std::string::npos);
  ekf.measurement_covariance = Eigen::Matrix2d{{1.0, 0.5}, {0.0, 1.0}};
  EXPECT_NE(refusal([&] { ekf.validate(); }).find("must be symmetric"), std::string::npos);
  ekf.measurement_covariance = Eigen::MatrixXd::Constant(1, 1, 1e-4);
  ekf.initial_covariance = Eigen::Matrix3d::Identity();  // valid alone, wrong size for n = 2
  EXPECT_EQ(refusal([&] { ekf.validate(); }), "(accepted)");
  EXPECT_NE(refusal([&] { ExtendedKalmanFilter<Linear2>(model, ekf); }).find("initial_covariance"),
            std::string::npos);
  ekf.initial_covariance.resize(0, 0);
  ekf.name = "tuned ekf";
  EXPECT_EQ(ExtendedKalmanFilter<Linear2>(model, ekf).name(), "tuned ekf");
}

// t_k = k·T: T from the options, else the model's step, else 1.
TEST(Harness, SampleTimeComesFromTheModelUnlessGiven) {
  SimulationOptions o;
  o.steps = 5;
  const Chua chua = paper_modified_chua();
  EXPECT_DOUBLE_EQ(simulate(chua, kTrue, o).t[4], 4.0 * chua.step());
  EXPECT_DOUBLE_EQ(simulate(Linear2{}, Eigen::Vector2d::Zero(), o).t[4], 4.0);
  const AnyModel any("modified-chua", chua, 0.25);
  EXPECT_DOUBLE_EQ(simulate(any, kTrue, o).t[4], 1.0);
  o.sample_time = 0.5;
  EXPECT_DOUBLE_EQ(simulate(chua, kTrue, o).t[4], 2.0);
  o.sample_time = 0.0;
  EXPECT_THROW(simulate(chua, kTrue, o), InvalidInput);
  o.sample_time = NAN;
  EXPECT_THROW(simulate(chua, kTrue, o), InvalidInput);
}

TEST(Harness, MseOnAHandCheckableCase) {
  Eigen::MatrixXd truth(2, 4), estimate(2, 4);
  truth << 0, 0, 0, 0, 1, 1, 1, 1;
  estimate << 1, 1, 0, 0, 1, 3, 1, 1;
  const Eigen::VectorXd all = mean_squared_error(truth, estimate);
  EXPECT_DOUBLE_EQ(all[0], 0.5);  // (1 + 1) / 4
  EXPECT_DOUBLE_EQ(all[1], 1.0);  // 4 / 4
  const Eigen::VectorXd after = mean_squared_error(truth, estimate, 2);
  EXPECT_DOUBLE_EQ(after[0], 0.0);
  EXPECT_DOUBLE_EQ(after[1], 0.0);
}

TEST(Harness, SeededNoiseIsReproducible) {
  const Measurements a = chua_data(50, 0.1), b = chua_data(50, 0.1);
  EXPECT_EQ(a.y, b.y);
  EXPECT_EQ(a.x, b.x);
  const Eigen::VectorXd noise = (a.y - chua_data(50).y).row(0).transpose();
  EXPECT_NEAR(std::sqrt(noise.squaredNorm() / 50.0), 0.1, 0.03);
  SimulationOptions bad;
  bad.noise_std = -1.0;
  EXPECT_THROW(simulate(paper_modified_chua(), kTrue, bad), InvalidInput);
}

TEST(AnyModel, MatchesTheStaticModelIncludingJacobians) {
  const AnyModel any("modified-chua", paper_modified_chua(), 0.05);
  const Chua model = paper_modified_chua();
  const Eigen::VectorXd x = kTrue;
  EXPECT_EQ(any.states(), 3);
  EXPECT_EQ(any.sample_time(), 0.05);
  EXPECT_LT((any.f(x, Eigen::VectorXd(0), 3) - model.f(kTrue, {}, 3)).norm(), 1e-15);
  // A window estimator over the run-time model recovers the state too.
  std::vector<std::unique_ptr<Observer>> observers;
  WindowEstimatorOptions options;
  options.initial_estimate = kGuess;
  observers.push_back(make_window_estimator(any, "newton:tol=1e-12", options));
  const Measurements data = chua_data(20);
  const auto r = run_observers(data, observers);
  EXPECT_LT((r.estimates[0].col(19) - data.x.col(19)).norm(), 1e-8);
}

}  // namespace
}  // namespace nlobs
