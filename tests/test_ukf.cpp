// The unscented Kalman filter: on a linear model with Gaussian noise it is the Kalman filter
// (compared with the EKF, which on a linear model is the Kalman filter too) at every step; on a
// nonlinear model it tracks; a covariance the Cholesky factorisation refuses is repaired, never
// an exception or NaN; missing and non-finite values; bad options; the `ukf` observer type.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "linear_gaussian.hpp"
#include "nlobs/models/modified_chua.hpp"
#include "nlobs/observers/baselines/baselines.hpp"
#include "nlobs/observers/baselines/unscented_kalman_filter.hpp"
#include "nlobs/registry/observer_types.hpp"
#include "test_support.hpp"

namespace nlobs {
namespace {

using test::Linear3;

using Exploding = test::Squaring;  // x⁺ = 1e200 x²: overflows at once

template <typename Options>
Options covariances(Options o) {
  return test::linear_statistics(std::move(o));
}

TEST(Ukf, OnALinearGaussianModelItIsTheKalmanFilter) {
  const Linear3 model;
  ExtendedKalmanFilter<Linear3> kalman(model, covariances(EkfOptions{}));
  for (const double alpha : {1.0, 0.5}) {  // any spread: the unscented transform is exact here
    UkfOptions o = covariances(UkfOptions{});
    o.alpha = alpha;
    UnscentedKalmanFilter<Linear3> ukf(model, o);
    kalman.reset();
    std::mt19937 rng(7);
    std::normal_distribution<double> noise(0.0, 0.05);
    Eigen::Vector3d x(1.0, 0.0, -1.0);
    double worst = 0.0;
    for (long k = 0; k < 200; ++k) {
      const Eigen::VectorXd u =
          Eigen::VectorXd::Constant(1, std::sin(0.1 * static_cast<double>(k)));
      Eigen::VectorXd y = model.h(x);
      y += Eigen::Vector2d(noise(rng), noise(rng));
      const Eigen::VectorXd e = kalman.step(k, static_cast<double>(k), y, u).estimate;
      const Eigen::VectorXd v = ukf.step(k, static_cast<double>(k), y, u).estimate;
      worst = std::max(worst, (v - e).norm() / std::max(1.0, e.norm()));
      x = model.f(x, Linear3::Input(u), k) + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    }
    EXPECT_LT(worst, 1e-9) << "alpha " << alpha;
    EXPECT_EQ(ukf.covariance_repairs(), 0);
  }
}

TEST(Ukf, TracksTheModifiedChuaFromAWrongStart) {
  const auto model = paper_modified_chua();
  using Model = std::decay_t<decltype(model)>;
  UkfOptions o;
  o.initial_estimate = Eigen::Vector3d(5.0, 10.0, -5.0);
  o.process_covariance = 1e-8 * Eigen::Matrix3d::Identity();
  o.measurement_covariance = Eigen::MatrixXd::Constant(1, 1, 1e-6);
  o.initial_covariance = 10.0 * Eigen::Matrix3d::Identity();
  UnscentedKalmanFilter<Model> ukf(model, o);
  Eigen::Vector3d x(1.0, 2.1428, -0.1648);
  const Eigen::VectorXd u(0);
  double last = 0.0;
  for (long k = 0; k < 3000; ++k) {
    const auto& s =
        ukf.step(k, static_cast<double>(k) * model.step(), Eigen::VectorXd(model.h(x)), u);
    EXPECT_TRUE(s.estimate.allFinite());
    last = (s.estimate - x).norm();
    x = model.f(x, Model::Input(u), k);
  }
  EXPECT_LT(last, 1e-3);
}

TEST(Ukf, ASingularCovarianceIsRepairedNotThrownAbout) {
  // P0 with a zero variance (a component known exactly) is positive semi-definite, as the options
  // allow, but Cholesky refuses it: the repair raises its diagonal by 1e-12, and the filter stays
  // the Kalman filter to that order.
  const Linear3 model;
  UkfOptions o = covariances(UkfOptions{});
  o.initial_covariance = Eigen::Vector3d(1.0, 0.0, 0.5).asDiagonal();
  EkfOptions e = covariances(EkfOptions{});
  e.initial_covariance = o.initial_covariance;
  UnscentedKalmanFilter<Linear3> ukf(model, o);
  ExtendedKalmanFilter<Linear3> kalman(model, e);
  for (long k = 0; k < 50; ++k) {
    const double t = static_cast<double>(k);
    const Eigen::VectorXd y = Eigen::Vector2d(std::cos(0.3 * t), std::sin(0.2 * t));
    const auto& s = ukf.step(k, t, y, Eigen::VectorXd::Zero(1));
    ASSERT_TRUE(s.estimate.allFinite()) << "k = " << k << ": " << s.failure_message;
    EXPECT_TRUE(s.failure.empty()) << s.failure_message;
    const Eigen::VectorXd x = kalman.step(k, t, y, Eigen::VectorXd::Zero(1)).estimate;
    EXPECT_LT((s.estimate - x).norm(), 1e-6) << "k = " << k;
  }
  EXPECT_GE(ukf.covariance_repairs(), 1);
}

TEST(Ukf, ATinySpreadOnABadlyScaledCovarianceStaysFinite) {
  // α = 1e-3 puts a weight of about −1e6 on the centre point; P0 spans 16 orders of magnitude.
  const Linear3 model;
  UkfOptions o = covariances(UkfOptions{});
  o.alpha = 1e-3;
  o.initial_covariance = Eigen::Vector3d(1e8, 1e-8, 1.0).asDiagonal();
  o.process_covariance = Eigen::Matrix3d::Zero();
  UnscentedKalmanFilter<Linear3> ukf(model, o);
  for (long k = 0; k < 100; ++k) {
    const double t = static_cast<double>(k);
    const Eigen::VectorXd y = Eigen::Vector2d(std::cos(0.3 * t), std::sin(0.2 * t));
    const auto& s = ukf.step(k, t, y, Eigen::VectorXd::Zero(1));
    ASSERT_TRUE(s.estimate.allFinite()) << "k = " << k << ": " << s.failure_message;
  }
}

TEST(Ukf, AnIndefiniteCovarianceRestartsFromP0AndSaysSo) {
  // A model that blows up: the predicted covariance overflows; the step keeps the last finite
  // estimate and P restarts from P0.
  UkfOptions o;
  o.initial_estimate = Eigen::VectorXd::Constant(1, 3.0);
  UnscentedKalmanFilter<Exploding> ukf(Exploding{}, o);
  EXPECT_TRUE(
      ukf.step(0, 0.0, Eigen::VectorXd::Constant(1, 3.0), Eigen::VectorXd(0)).failure.empty());
  const auto& s = ukf.step(1, 1.0, Eigen::VectorXd::Constant(1, 3.0), Eigen::VectorXd(0));
  EXPECT_EQ(s.failure, "non_finite_estimate");
  EXPECT_NE(s.failure_message.find("ukf: the prediction at sample k = 1"), std::string::npos)
      << s.failure_message;
  EXPECT_TRUE(s.estimate.allFinite());
  const auto& next = ukf.step(2, 2.0, Eigen::VectorXd::Constant(1, 3.0), Eigen::VectorXd(0));
  EXPECT_TRUE(next.estimate.allFinite());
}

// A sample may carry only some outputs: the UKF and the EKF update with those (their rows of h
// and their block of R), as the Kalman filter written out does; none measured is a missing
// sample.
TEST(Ukf, APartlyMeasuredSampleUpdatesWithTheOutputsItHas) {
  const Linear3 model;
  UnscentedKalmanFilter<Linear3> ukf(model, covariances(UkfOptions{}));
  ExtendedKalmanFilter<Linear3> ekf(model, covariances(EkfOptions{}));
  test::KalmanReference kalman;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (long k = 0; k < 30; ++k) {
    const double t = static_cast<double>(k);
    Eigen::Vector2d y(std::cos(0.3 * t), 0.1 * t);
    if (k % 3 == 1) y[0] = nan;
    if (k % 5 == 2) y[1] = nan;
    if (k == 20) y.setConstant(nan);
    const bool none = !y.array().isFinite().any();  // k = 7, 20, 22
    const Eigen::Vector3d reference = kalman.step(y, 0.2);
    const Eigen::VectorXd u = Eigen::VectorXd::Constant(1, 0.2);
    const auto& s = ukf.step(k, t, y, u);
    EXPECT_EQ(s.measurement_missing, none) << k;
    EXPECT_LT((s.estimate - reference).norm(), 1e-9 * std::max(1.0, reference.norm())) << k;
    const auto& e = ekf.step(k, t, y, u);
    EXPECT_EQ(e.measurement_missing, none) << k;
    EXPECT_LT((e.estimate - reference).norm(), 1e-9 * std::max(1.0, reference.norm())) << k;
  }
}

TEST(Ukf, BadOptionsAreRefusedByName) {
  const Linear3 model;
  auto message = [&](UkfOptions o) {
    return test::message_of([&] { UnscentedKalmanFilter<Linear3>(model, std::move(o)); });
  };
  UkfOptions o = covariances(UkfOptions{});
  o.alpha = 0.0;
  EXPECT_NE(message(o).find("UkfOptions::alpha must lie in (0, 1]"), std::string::npos);
  o = covariances(UkfOptions{});
  o.beta = -1.0;
  EXPECT_NE(message(o).find("UkfOptions::beta"), std::string::npos);
  o = covariances(UkfOptions{});
  o.kappa = -3.0;  // n + λ = 0
  EXPECT_NE(message(o).find("UkfOptions::kappa"), std::string::npos) << message(o);
  o = covariances(UkfOptions{});
  o.process_covariance(0, 1) = 0.5;  // not symmetric
  EXPECT_NE(message(o).find("UkfOptions::process_covariance must be symmetric"), std::string::npos)
      << message(o);
  o = covariances(UkfOptions{});
  o.measurement_covariance = -Eigen::Matrix2d::Identity();
  EXPECT_NE(message(o).find("measurement_covariance must be positive semi-definite"),
            std::string::npos);
  o = covariances(UkfOptions{});
  o.initial_covariance = Eigen::Matrix2d::Identity();
  EXPECT_NE(message(o).find("initial_covariance"), std::string::npos);
  o = covariances(UkfOptions{});
  o.initial_estimate = Eigen::Vector2d(0.0, 0.0);
  EXPECT_NE(message(o).find("initial_estimate"), std::string::npos);
}

TEST(Ukf, IsAnObserverTypeOfTheRegistry) {
  const auto& entry = observer_type_registry().get("ukf");
  EXPECT_NE(entry.description.find("unscented"), std::string::npos);
}

}  // namespace
}  // namespace nlobs
