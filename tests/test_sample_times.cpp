// Samples with times, on models nlobs does not ship: the EKF, UKF and MHE integrate a model with
// a flow over irregular intervals and are then the Kalman filter of the exact transition (Q
// weighted by the interval); a dropped row on the grid is a missing sample for every
// discrete-time observer; a fixed-step model, and observers whose gain assumes the grid, refuse
// a sample off it, naming it; times that go back or are not finite are named; two partial
// samples of one instant are one sample; the MHE takes a late measurement and gives the
// estimate of the same data in order, and drops (and counts) one older than its horizon.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "linear_gaussian.hpp"
#include "nlobs/models/discretization.hpp"
#include "nlobs/models/modified_chua.hpp"
#include "nlobs/models/systems.hpp"
#include "nlobs/observers/baselines/baselines.hpp"
#include "nlobs/observers/baselines/unscented_kalman_filter.hpp"
#include "nlobs/observers/core/simulation.hpp"
#include "nlobs/observers/mhe/mhe_estimator.hpp"
#include "nlobs/observers/window/window_estimator.hpp"
#include "test_support.hpp"

namespace nlobs {
namespace {

using test::KalmanReference;
using test::Linear3;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kStep = 0.1;

// x' = A x + B u, y = C x in continuous time: discretised by RK4 it has a flow over any
// interval, and that flow is linear, x(t + dt) = Φ(dt) x + Γ(dt) u.
struct LinearContinuous : ModelSizes<3, 1, 2> {
  Eigen::Matrix3d a{{-0.1, 1.0, 0.0}, {-1.0, -0.1, 0.5}, {0.0, 0.0, -0.2}};
  Eigen::Vector3d b{0.0, 1.0, 0.5};
  Eigen::Matrix<double, 2, 3> c = Linear3{}.c;
  template <typename T>
  State<T> vector_field(const State<T>& x, const Input& u, double) const {
    return a.cast<T>() * x + (b * u[0]).cast<T>();
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return c.cast<T>() * x;
  }
};
using Sampled = Discretized<LinearContinuous>;

Sampled sampled() {
  return Sampled(LinearContinuous{}, kStep, Scheme::kRk4);
}

// The reference's prediction over dt, as SampleClock moves: m steps of T on the grid, else one
// flow over dt with Q weighted by dt / T.
void predict_over(KalmanReference& kalman, const Sampled& model, double t, double dt, double u) {
  const auto transition = [&](double from, double length, double weight) {
    Eigen::Matrix3d phi;
    for (int i = 0; i < 3; ++i) {
      phi.col(i) = model.flow(Eigen::Vector3d(Eigen::Vector3d::Unit(i)), Sampled::Input::Zero(),
                              from, length);
    }
    const Eigen::Vector3d gamma_u = model.flow(Eigen::Vector3d(Eigen::Vector3d::Zero()),
                                               Sampled::Input::Constant(u), from, length);
    kalman.predict(phi, gamma_u, weight);
  };
  const double m = std::round(dt / kStep);
  if (m >= 1.0 && std::abs(dt / kStep - m) <= 1e-6) {
    for (int j = 0; j < static_cast<int>(m); ++j) transition(t + j * kStep, kStep, 1.0);
  } else {
    transition(t, dt, dt / kStep);
  }
}

// Irregular times: on the grid, off it, gaps of two and three steps.
std::vector<double> irregular_times(int count) {
  const double intervals[] = {0.1, 0.137, 0.2, 0.05, 0.1, 0.31, 0.3, 0.0713, 0.1, 0.42};
  std::vector<double> t{0.0};
  for (int i = 1; i < count; ++i) t.push_back(t.back() + intervals[i % 10]);
  return t;
}

Eigen::Vector2d output_at(double t) {
  return Eigen::Vector2d(std::cos(0.7 * t), 0.3 * t);
}
double input_at(double t) {
  return std::sin(0.5 * t);
}

TEST(SampleTimes, KalmanTypeObserversIntegrateOverTheActualInterval) {
  const Sampled model = sampled();
  ExtendedKalmanFilter<Sampled> ekf(model, test::linear_statistics(EkfOptions{}));
  UnscentedKalmanFilter<Sampled> ukf(model, test::linear_statistics(UkfOptions{}));
  MheOptions mo = test::linear_statistics(MheOptions{});
  mo.horizon = 5;
  MheEstimator<Sampled> mhe(model, mo);
  KalmanReference kalman;
  const std::vector<double> times = irregular_times(60);
  double worst[3] = {0.0, 0.0, 0.0};
  for (std::size_t k = 0; k < times.size(); ++k) {
    const double t = times[k];
    if (k > 0) predict_over(kalman, model, times[k - 1], t - times[k - 1], input_at(times[k - 1]));
    Eigen::Vector2d y = output_at(t);
    if (k % 7 == 3) y[1] = kNaN;  // partly measured samples too
    kalman.update(y);
    const Eigen::VectorXd u = Eigen::VectorXd::Constant(1, input_at(t));
    const long kk = static_cast<long>(k);
    Observer* observers[3] = {&ekf, &ukf, &mhe};
    for (int i = 0; i < 3; ++i) {
      const ObserverStep& s = observers[i]->step(kk, t, y, u);
      ASSERT_TRUE(s.failure.empty()) << observers[i]->name() << ": " << s.failure_message;
      worst[i] =
          std::max(worst[i], (s.estimate - kalman.x).norm() / std::max(1.0, kalman.x.norm()));
    }
  }
  EXPECT_LT(worst[0], 1e-9) << "ekf";
  EXPECT_LT(worst[1], 1e-9) << "ukf";
  EXPECT_LT(worst[2], 1e-9) << "mhe";
}

// Every discrete-time observer: a row that is absent from the data (its time skipped on the
// grid) gives the estimates of the same row present with y missing.
TEST(SampleTimes, ADroppedRowOnTheGridIsAMissingSample) {
  const auto model = paper_modified_chua();
  using Model = std::decay_t<decltype(model)>;
  SimulationOptions so;
  so.steps = 60;
  so.noise_std = 1e-3;
  const Measurements data = simulate(model, Eigen::Vector3d(1.0, 2.1428, -0.1648), so);
  const Eigen::Vector3d guess(1.2, 2.0, 0.0);
  auto observers = [&] {
    std::vector<std::unique_ptr<Observer>> list;
    EkfOptions e;
    e.initial_estimate = guess;
    list.push_back(std::make_unique<ExtendedKalmanFilter<Model>>(model, e));
    UkfOptions u;
    u.initial_estimate = guess;
    list.push_back(std::make_unique<UnscentedKalmanFilter<Model>>(model, u));
    MheOptions m;
    m.initial_estimate = guess;
    m.horizon = 6;
    list.push_back(std::make_unique<MheEstimator<Model>>(model, m));
    LuenbergerOptions l;
    l.initial_estimate = guess;
    l.gain = Eigen::Vector3d(0.2, 0.1, 0.0);
    list.push_back(std::make_unique<LuenbergerObserver<Model>>(model, l));
    WindowEstimatorOptions w;
    w.initial_estimate = guess;
    list.push_back(make_window_estimator(model, "newton", w));
    return list;
  };
  auto present = observers(), dropped = observers();
  const Eigen::VectorXd none(0);
  for (long k = 0; k < data.steps(); ++k) {
    const Eigen::VectorXd y = k == 17 ? Eigen::VectorXd(Eigen::VectorXd::Constant(1, kNaN))
                                      : Eigen::VectorXd(data.y.col(k));
    for (std::size_t i = 0; i < present.size(); ++i) {
      const Eigen::VectorXd a = present[i]->step(k, data.t[k], y, none).estimate;
      if (k == 17) continue;  // the row that is not there
      const ObserverStep& s = dropped[i]->step(k, data.t[k], y, none);
      ASSERT_TRUE(s.failure.empty()) << present[i]->name() << ": " << s.failure_message;
      EXPECT_LT((s.estimate - a).norm(), 1e-12 * std::max(1.0, a.norm()))
          << present[i]->name() << " k = " << k;
    }
  }
}

TEST(SampleTimes, AFixedStepModelRefusesASampleOffItsGridAndNamesIt) {
  // Linear3 is a map in discrete time that declares no sample time: its first interval is T.
  for (const char* which : {"ekf", "ukf", "mhe"}) {
    std::unique_ptr<Observer> observer;
    if (std::string(which) == "ekf") {
      observer = std::make_unique<ExtendedKalmanFilter<Linear3>>(
          Linear3{}, test::linear_statistics(EkfOptions{}));
    } else if (std::string(which) == "ukf") {
      observer = std::make_unique<UnscentedKalmanFilter<Linear3>>(
          Linear3{}, test::linear_statistics(UkfOptions{}));
    } else {
      observer =
          std::make_unique<MheEstimator<Linear3>>(Linear3{}, test::linear_statistics(MheOptions{}));
    }
    const Eigen::VectorXd u = Eigen::VectorXd::Zero(1);
    for (long k = 0; k < 3; ++k) {
      observer->step(k, 0.5 * static_cast<double>(k), output_at(static_cast<double>(k)), u);
    }
    const Eigen::VectorXd before = observer->step(3, 1.5, output_at(3.0), u).estimate;
    const ObserverStep& off = observer->step(4, 1.8, output_at(4.0), u);
    EXPECT_EQ(off.failure, "non_uniform") << which;
    EXPECT_NE(off.failure_message.find("sample k = 4 at t = 1.8"), std::string::npos)
        << off.failure_message;
    EXPECT_NE(off.failure_message.find("not a multiple of T = 0.5"), std::string::npos)
        << off.failure_message;
    EXPECT_NE(off.failure_message.find("fixed step"), std::string::npos) << off.failure_message;
    EXPECT_EQ(off.estimate, before) << which;
    const ObserverStep& next = observer->step(5, 2.0, output_at(4.0), u);
    EXPECT_TRUE(next.failure.empty()) << which << ": " << next.failure_message;
  }
}

TEST(SampleTimes, ConstantGainObserversNeedTheGridEvenWithAFlow) {
  const Sampled model = sampled();
  LuenbergerOptions l;
  l.initial_estimate = Eigen::Vector3d::Zero();
  l.gain = Eigen::Matrix<double, 3, 2>::Constant(0.1);
  LuenbergerObserver<Sampled> luenberger(model, l);
  SlidingModeOptions m;
  m.initial_estimate = Eigen::Vector3d::Zero();
  m.q = m.r = Eigen::Matrix<double, 3, 2>::Constant(0.1);
  SlidingModeObserver<Sampled> sliding(model, m);
  WindowEstimatorOptions w;
  w.initial_estimate = Eigen::Vector3d::Zero();
  auto window = make_window_estimator(model, "ceres", w);
  Observer* observers[3] = {&luenberger, &sliding, window.get()};
  const char* reasons[3] = {"constant gain", "constant gain", "window map"};
  const Eigen::VectorXd u = Eigen::VectorXd::Zero(1);
  for (int i = 0; i < 3; ++i) {
    observers[i]->step(0, 0.0, output_at(0.0), u);
    EXPECT_TRUE(observers[i]->step(1, 0.3, output_at(0.3), u).failure.empty());  // a gap
    const ObserverStep& off = observers[i]->step(2, 0.35, output_at(0.35), u);
    EXPECT_EQ(off.failure, "non_uniform");
    EXPECT_NE(off.failure_message.find(reasons[i]), std::string::npos) << off.failure_message;
    const ObserverStep& same = observers[i]->step(3, 0.3, output_at(0.3), u);
    EXPECT_EQ(same.failure, "non_uniform");
    EXPECT_NE(same.failure_message.find("last sample's time"), std::string::npos)
        << same.failure_message;
  }
}

TEST(SampleTimes, TimesThatGoBackOrAreNotFiniteAreNamed) {
  ExtendedKalmanFilter<Sampled> ekf(sampled(), test::linear_statistics(EkfOptions{}));
  const Eigen::VectorXd u = Eigen::VectorXd::Zero(1);
  ekf.step(0, 0.0, output_at(0.0), u);
  const Eigen::VectorXd kept = ekf.step(1, 0.1, output_at(0.1), u).estimate;
  const ObserverStep& back = ekf.step(2, 0.05, output_at(0.05), u);
  EXPECT_EQ(back.failure, "non_uniform");
  EXPECT_NE(back.failure_message.find("does not come after the last sample's (t = 0.1)"),
            std::string::npos)
      << back.failure_message;
  EXPECT_EQ(back.estimate, kept);
  const ObserverStep& nan = ekf.step(3, kNaN, output_at(0.2), u);
  EXPECT_EQ(nan.failure, "non_finite");
  EXPECT_EQ(nan.estimate, kept);
  const ObserverStep& huge = ekf.step(4, 1e300, output_at(0.2), u);
  EXPECT_EQ(huge.failure, "non_uniform");  // T cannot be resolved at 1e300
  EXPECT_TRUE(ekf.step(5, 0.2, output_at(0.2), u).failure.empty());
}

// A sample that carries y1 and one that carries y2 at the same instant are the sample that
// carries both (R diagonal: the two outputs' noises are independent).
TEST(SampleTimes, TwoPartialSamplesOfOneInstantAreOneSample) {
  EkfOptions e = test::linear_statistics(EkfOptions{});
  e.measurement_covariance = Eigen::Vector2d(1e-2, 5e-3).asDiagonal();
  UkfOptions u = test::linear_statistics(UkfOptions{});
  u.measurement_covariance = e.measurement_covariance;
  MheOptions m = test::linear_statistics(MheOptions{});
  m.measurement_covariance = e.measurement_covariance;
  m.horizon = 4;
  const Sampled model = sampled();
  std::vector<std::unique_ptr<Observer>> split, whole;
  for (auto* list : {&split, &whole}) {
    list->push_back(std::make_unique<ExtendedKalmanFilter<Sampled>>(model, e));
    list->push_back(std::make_unique<UnscentedKalmanFilter<Sampled>>(model, u));
    list->push_back(std::make_unique<MheEstimator<Sampled>>(model, m));
  }
  const Eigen::VectorXd input = Eigen::VectorXd::Constant(1, 0.3);
  long k = 0;
  for (int i = 0; i < 20; ++i) {
    const double t = kStep * i;
    const Eigen::Vector2d y = output_at(t);
    for (std::size_t o = 0; o < split.size(); ++o) {
      split[o]->step(k, t, Eigen::Vector2d(y[0], kNaN), input);
      const ObserverStep& second = split[o]->step(k + 1, t, Eigen::Vector2d(kNaN, y[1]), input);
      ASSERT_TRUE(second.failure.empty()) << second.failure_message;
      const Eigen::VectorXd reference = whole[o]->step(i, t, y, input).estimate;
      EXPECT_LT((second.estimate - reference).norm(), 1e-9 * std::max(1.0, reference.norm()))
          << split[o]->name() << " t = " << t;
    }
    k += 2;
  }
  // The MHE holds one value per output and instant: a second y1 at t is refused, by name.
  const ObserverStep& again = split[2]->step(k, kStep * 19, Eigen::Vector2d(1.0, kNaN), input);
  EXPECT_EQ(again.failure, "duplicate_measurement");
  EXPECT_NE(again.failure_message.find("measures output 1"), std::string::npos)
      << again.failure_message;
}

// The same samples in order, and with sample `late` delivered after sample late + 2: from the
// late delivery on, the MHE's estimates are those of the samples in order (compared at the same
// latest sample).
template <typename Model>
double late_against_in_order(const Model& model, const MheOptions& options,
                             const std::vector<double>& times, std::size_t late,
                             double input = 0.0) {
  MheEstimator<Model> in_order(model, options), delayed(model, options);
  const Eigen::VectorXd u = Eigen::VectorXd::Constant(model.inputs(), input);
  auto y = [&](std::size_t i) {
    return Eigen::VectorXd(output_at(times[i]).head(model.outputs()));
  };
  std::vector<Eigen::VectorXd> reference;
  for (std::size_t i = 0; i < times.size(); ++i) {
    reference.push_back(in_order.step(static_cast<long>(i), times[i], y(i), u).estimate);
  }
  double worst = 0.0;
  for (std::size_t i = 0; i < times.size(); ++i) {
    if (i == late) continue;
    const long k = static_cast<long>(i);
    const ObserverStep* s = &delayed.step(k, times[i], y(i), u);
    EXPECT_TRUE(s->failure.empty()) << s->failure_message;
    if (i == late + 2) {
      s = &delayed.step(static_cast<long>(late), times[late], y(late), u);
      EXPECT_TRUE(s->failure.empty()) << s->failure_message;
    }
    if (i >= late + 2) {
      worst =
          std::max(worst, (s->estimate - reference[i]).norm() / std::max(1.0, reference[i].norm()));
    }
  }
  return worst;
}

TEST(SampleTimes, AMheGivenALateMeasurementGivesTheEstimateOfTheDataInOrder) {
  MheOptions o = test::linear_statistics(MheOptions{});
  o.horizon = 5;
  // A flow: the late sample becomes a node between its neighbours, at irregular times.
  EXPECT_LT(late_against_in_order(sampled(), o, irregular_times(40), 20, 0.2), 1e-9);
  EXPECT_LT(late_against_in_order(sampled(), o, irregular_times(40), 6, 0.2), 1e-9);
  // A late sample whose split brings grid steps (nodes without a measurement) and overflows a
  // short horizon: the nodes it brings are taken as in order before any of them leaves.
  MheOptions short_horizon = o;
  short_horizon.horizon = 3;
  EXPECT_LT(late_against_in_order(sampled(), short_horizon,
                                  {0.0, 0.3, 0.75, 0.85, 0.95, 1.05, 1.15, 1.5}, 1, 0.2),
            1e-9);
  // A fixed-step map: the late sample fills the node of its grid point.
  std::vector<double> grid;
  for (int i = 0; i < 40; ++i) grid.push_back(static_cast<double>(i));
  EXPECT_LT(late_against_in_order(Linear3{}, o, grid, 20, 0.2), 1e-9);
  // A nonlinear model with bounds (the batch reactor): the same answer while the late sample is
  // in the horizon.
  const Discretized<BatchReactor> reactor(BatchReactor{}, 0.25, Scheme::kRk4);
  MheOptions b;
  b.initial_estimate = Eigen::Vector3d(1.0, 0.0, 4.0);
  b.initial_covariance = 0.25 * Eigen::Matrix3d::Identity();
  b.process_covariance = 1e-6 * Eigen::Matrix3d::Identity();
  b.measurement_covariance = Eigen::MatrixXd::Constant(1, 1, 0.0625);
  b.lower_bounds = Eigen::Vector3d::Zero();
  b.horizon = 10;
  std::vector<double> short_run;
  for (int i = 0; i < 16; ++i) short_run.push_back(0.25 * i);
  EXPECT_LT(late_against_in_order(reactor, b, short_run, 12), 1e-7);
}

TEST(SampleTimes, AMeasurementOlderThanTheHorizonIsDroppedAndCounted) {
  MheOptions o = test::linear_statistics(MheOptions{});
  o.horizon = 3;
  MheEstimator<Sampled> mhe(sampled(), o);
  const Eigen::VectorXd u = Eigen::VectorXd::Zero(1);
  for (long k = 0; k < 6; ++k) {
    const double t = kStep * static_cast<double>(k);
    mhe.step(k, t, output_at(t), u);
  }
  const Eigen::VectorXd kept = mhe.horizon_estimates().rightCols(1);
  const ObserverStep& old = mhe.step(6, 0.15, output_at(0.15), u);
  EXPECT_EQ(old.failure, "late_measurement_dropped");
  EXPECT_NE(old.failure_message.find("older than the horizon's first sample (t = 0.3)"),
            std::string::npos)
      << old.failure_message;
  EXPECT_EQ(old.estimate, kept);
  mhe.step(7, 0.05, output_at(0.05), u);
  EXPECT_EQ(mhe.late_measurements_dropped(), 2);
  ASSERT_EQ(mhe.info().warnings.size(), 1u);
  EXPECT_NE(mhe.info().warnings[0].find("2 late measurement(s)"), std::string::npos)
      << mhe.info().warnings[0];
  mhe.reset();
  EXPECT_EQ(mhe.late_measurements_dropped(), 0);
  EXPECT_TRUE(mhe.info().warnings.empty());
}

}  // namespace
}  // namespace nlobs
