#pragma once
// The classic observers the window estimators are compared with ([MGFF23]), for any discrete
// model x⁺ = f(x, u, k), y = h(x). Each reports x̂_k from the samples up to k − 1 (Luenberger,
// sliding mode: eq. 89 form, x̂_{k+1} = f(x̂_k) + correction(y_k)) or up to k (EKF: filtered).
// Each is built as X(model, XOptions): the options hold the name, the initial estimate and the
// gains; XOptions::validate() (called by the constructor) checks what the options alone can
// tell, the constructor the sizes against the model.
#include <Eigen/LU>
#include <cmath>
#include <sstream>
#include <string>

#include "nlobs/models/model.hpp"
#include "nlobs/observers/core/discrete_jacobians.hpp"
#include "nlobs/observers/core/observer.hpp"
#include "nlobs/observers/core/option_checks.hpp"
#include "nlobs/solvers/status.hpp"

namespace nlobs {

struct LuenbergerOptions {
  std::string name = "luenberger";   // in reports
  Eigen::VectorXd initial_estimate;  // x̂_0: n finite numbers (required)
  Eigen::MatrixXd gain;              // L: n × p, finite (required)
  // Throws InvalidInput naming the field: an empty name, an initial estimate or gain that is
  // empty or not finite.
  void validate() const;
};

struct SlidingModeOptions {
  std::string name = "sliding_mode";  // in reports
  Eigen::VectorXd initial_estimate;   // x̂_0: n finite numbers (required)
  Eigen::MatrixXd q;                  // Q: n × p linear gain, finite (required)
  Eigen::MatrixXd r;                  // R: n × p switching gain, finite (required)
  double gamma = 1.0;                 // γ > 0: the boundary layer of sat(e / γ)
  // Throws InvalidInput naming the field: as LuenbergerOptions, and γ ≤ 0 or not finite.
  void validate() const;
};

// x̂⁺ = f(x̂, u, k) + L (y − h(x̂)), constant gain L (n × p). A next estimate that is not finite
// (an unstable gain, a model that overflows) is not taken: the step says so, x̂ stays.
template <DiscreteModel Model>
class LuenbergerObserver final : public Observer {
 public:
  LuenbergerObserver(Model model, LuenbergerOptions options)
      : model_(std::move(model)), options_(detail::validated(std::move(options))) {
    detail::require_shape("LuenbergerOptions", "gain", options_.gain, model_.states(),
                          model_.outputs());
    detail::require_size("LuenbergerOptions", "initial_estimate", options_.initial_estimate,
                         model_.states());
    info_.name = options_.name;
    reset();
  }
  void reset() override { x_ = options_.initial_estimate; }
  const ObserverStep& step(long k, double /*t*/, const Eigen::VectorXd& y,
                           const Eigen::VectorXd& u) override {
    step_.estimate = x_;
    step_.failure.clear();
    step_.failure_message.clear();
    step_.measurement_missing = !y.allFinite();
    Eigen::VectorXd next = f(x_, u, k);
    if (!step_.measurement_missing) next += options_.gain * (y - h(x_));
    accept_finite(next, x_, step_, name(), k);  // an unstable gain L overflows: say so
    return step_;
  }

 private:
  Eigen::VectorXd f(const Eigen::VectorXd& x, const Eigen::VectorXd& u, long k) const {
    return model_.f(ModelVector<double, Model::kStates>(x), ModelVector<double, Model::kInputs>(u),
                    k);
  }
  Eigen::VectorXd h(const Eigen::VectorXd& x) const {
    return model_.h(ModelVector<double, Model::kStates>(x));
  }
  Model model_;
  LuenbergerOptions options_;
  Eigen::VectorXd x_;
  ObserverStep step_;
};

// x̂⁺ = f(x̂, u, k) + Q e + R sat(e / γ), e = y − h(x̂), sat = clamp to [−1, 1] per entry
// (Q, R: n × p gains; γ > 0 the boundary layer).
template <DiscreteModel Model>
class SlidingModeObserver final : public Observer {
 public:
  SlidingModeObserver(Model model, SlidingModeOptions options)
      : model_(std::move(model)), options_(detail::validated(std::move(options))) {
    const Eigen::Index n = model_.states(), p = model_.outputs();
    detail::require_shape("SlidingModeOptions", "q", options_.q, n, p);
    detail::require_shape("SlidingModeOptions", "r", options_.r, n, p);
    detail::require_size("SlidingModeOptions", "initial_estimate", options_.initial_estimate, n);
    info_.name = options_.name;
    reset();
  }
  void reset() override { x_ = options_.initial_estimate; }
  const ObserverStep& step(long k, double /*t*/, const Eigen::VectorXd& y,
                           const Eigen::VectorXd& u) override {
    step_.estimate = x_;
    step_.failure.clear();
    step_.failure_message.clear();
    step_.measurement_missing = !y.allFinite();
    Eigen::VectorXd next = model_.f(ModelVector<double, Model::kStates>(x_),
                                    ModelVector<double, Model::kInputs>(u), k);
    if (!step_.measurement_missing) {
      const Eigen::VectorXd e =
          y - Eigen::VectorXd(model_.h(ModelVector<double, Model::kStates>(x_)));
      next += options_.q * e + options_.r * (e / options_.gamma).cwiseMax(-1.0).cwiseMin(1.0);
    }
    accept_finite(next, x_, step_, name(), k);
    return step_;
  }

 private:
  Model model_;
  SlidingModeOptions options_;
  Eigen::VectorXd x_;
  ObserverStep step_;
};

// Extended Kalman filter with Jacobians of f and h by forward-mode AD (ceres::Jet):
//   update with y_k:  K = P Hᵀ (H P Hᵀ + R)⁻¹, x̂ ← x̂ + K (y − h(x̂)), P ← (I − K H) P (I − K H)ᵀ + K
//   R Kᵀ report x̂_k, then predict: x̂ ← f(x̂, u_k, k), P ← F P Fᵀ + Q.
// An update or prediction that is not finite is not taken (the step says so): the estimate
// keeps its last finite value, and a non-finite predicted covariance restarts from P0.
struct EkfOptions {
  std::string name = "ekf";                // in reports
  Eigen::VectorXd initial_estimate;        // x̂_0: n finite numbers (required)
  Eigen::MatrixXd process_covariance;      // Q (n × n); empty: 1e-6 I
  Eigen::MatrixXd measurement_covariance;  // R (p × p); empty: 1e-4 I
  Eigen::MatrixXd initial_covariance;      // P0 (n × n); empty: I
  // Throws InvalidInput naming the field: an empty name, an initial estimate that is empty or
  // not finite, a covariance given but not square, finite, symmetric positive semi-definite.
  void validate() const;
};

template <DiscreteModel Model>
class ExtendedKalmanFilter final : public Observer {
 public:
  ExtendedKalmanFilter(Model model, EkfOptions options)
      : model_(std::move(model)), initial_(options.initial_estimate) {
    options.validate();
    info_.name = options.name;
    const Eigen::Index n = model_.states(), p = model_.outputs();
    const detail::Covariances c = detail::covariances_of("EkfOptions", options, n, p);
    q_ = c.process;
    r_ = c.measurement;
    p0_ = c.initial;
    detail::require_size("EkfOptions", "initial_estimate", initial_, n);
    reset();
  }
  void reset() override {
    x_ = initial_;
    p_ = p0_;
  }
  const ObserverStep& step(long k, double /*t*/, const Eigen::VectorXd& y,
                           const Eigen::VectorXd& u) override {
    const Eigen::Index n = model_.states();
    step_.failure.clear();
    step_.failure_message.clear();
    step_.measurement_missing = !y.allFinite();
    if (!step_.measurement_missing) {
      Eigen::MatrixXd hj;
      jacobian_h(x_, hj);
      const Eigen::MatrixXd s = hj * p_ * hj.transpose() + r_;
      const Eigen::MatrixXd gain = p_ * hj.transpose() * s.inverse();
      const Eigen::VectorXd innovation =
          y - Eigen::VectorXd(model_.h(ModelVector<double, Model::kStates>(x_)));
      const Eigen::VectorXd updated = x_ + gain * innovation;
      const Eigen::MatrixXd ikh = Eigen::MatrixXd::Identity(n, n) - gain * hj;
      const Eigen::MatrixXd covariance =
          ikh * p_ * ikh.transpose() + gain * r_ * gain.transpose();  // Joseph form
      if (updated.allFinite() && covariance.allFinite()) {
        x_ = updated;
        p_ = covariance;
      } else {
        predicted_failure(k, "the measurement update", "kept the last finite estimate");
      }
    }
    step_.estimate = x_;
    Eigen::MatrixXd fj;
    jacobian_f(x_, u, k, fj);
    const Eigen::VectorXd predicted = model_.f(ModelVector<double, Model::kStates>(x_),
                                               ModelVector<double, Model::kInputs>(u), k);
    const Eigen::MatrixXd covariance = fj * p_ * fj.transpose() + q_;
    if (accept_finite(predicted, x_, step_, name(), k, "the predicted state")) {
      if (covariance.allFinite()) {
        p_ = covariance;
      } else {  // restart the covariance from P0 so that the filter can re-acquire
        predicted_failure(k, "the predicted covariance P", "P restarts from P0");
        p_ = p0_;
      }
    }
    return step_;
  }

 private:
  void jacobian_f(const Eigen::VectorXd& x, const Eigen::VectorXd& u, long k,
                  Eigen::MatrixXd& j) const {
    Matrix<Model::kStates, Model::kStates> jac;
    state_jacobian(model_, ModelVector<double, Model::kStates>(x),
                   ModelVector<double, Model::kInputs>(u), k, jac);
    j = jac;
  }
  void jacobian_h(const Eigen::VectorXd& x, Eigen::MatrixXd& j) const {
    Matrix<Model::kOutputs, Model::kStates> jac;
    output_jacobian(model_, ModelVector<double, Model::kStates>(x), jac);
    j = jac;
  }

  void predicted_failure(long k, const char* what, const char* action) {
    std::ostringstream os;
    os << name() << ": " << what << " at sample k = " << k << " is not finite; " << action;
    mark_non_finite_estimate(step_, os.str());
  }

  Model model_;
  Eigen::VectorXd initial_, x_;
  Eigen::MatrixXd q_, r_, p0_, p_;
  ObserverStep step_;
};

}  // namespace nlobs
