#pragma once
// The classic observers the window estimators are compared with ([MGFF23]), for any discrete
// model x⁺ = f(x, u, k), y = h(x). Each reports x̂_k from the samples up to k − 1 (Luenberger,
// sliding mode: eq. 89 form, x̂_{k+1} = f(x̂_k) + correction(y_k)) or up to k (EKF: filtered).
// Samples are placed by their times (SampleClock): a gap on the model's grid is that many
// steps without a measurement; an interval off the grid is integrated by the EKF (a model with
// a flow, Q scaled by the interval) and refused by Luenberger and sliding mode, whose constant
// gains are designed for the step T (failure "non_uniform"). A sample may carry only some
// outputs: the EKF updates with those measured; Luenberger and sliding mode correct with the
// measured entries of y − h(x̂) (the others count 0).
// Each is built as X(model, XOptions): the options hold the name, the initial estimate and the
// gains; XOptions::validate() (called by the constructor) checks what the options alone can
// tell, the constructor the sizes against the model.
#include <Eigen/LU>
#include <cmath>
#include <sstream>
#include <string>

#include "nlobs/models/model.hpp"
#include "nlobs/observers/core/discrete_jacobians.hpp"
#include "nlobs/observers/core/move_covariance.hpp"
#include "nlobs/observers/core/observer.hpp"
#include "nlobs/observers/core/option_checks.hpp"
#include "nlobs/observers/core/predict_update_observer.hpp"
#include "nlobs/observers/core/sample_clock.hpp"
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

// Why Luenberger and sliding mode refuse a sample off the model's grid.
inline constexpr const char* kConstantGain = "its constant gain is designed for the step T";

// y − h(x) with 0 where y was not measured.
template <DiscreteModel Model>
Eigen::VectorXd measured_error(const Model& model, const Eigen::VectorXd& x,
                               const Eigen::VectorXd& y) {
  const Eigen::VectorXd e = y - Eigen::VectorXd(model.h(ModelVector<double, Model::kStates>(x)));
  return y.array().isFinite().select(e, 0.0);
}

// x̂⁺ = f(x̂, u, k) + L (y − h(x̂)), constant gain L (n × p). A next estimate that is not finite
// (an unstable gain, a model that overflows) is not taken: the step says so, x̂ stays.
template <DiscreteModel Model>
class LuenbergerObserver final
    : public detail::PredictUpdateObserver<Model, LuenbergerObserver<Model>> {
  using Base = detail::PredictUpdateObserver<Model, LuenbergerObserver<Model>>;
  friend Base;

 public:
  LuenbergerObserver(Model model, LuenbergerOptions options)
      : Base(std::move(model), kConstantGain, false),
        options_(detail::validated(std::move(options))) {
    detail::require_shape("LuenbergerOptions", "gain", options_.gain, this->model_.states(),
                          this->model_.outputs());
    detail::require_size("LuenbergerOptions", "initial_estimate", options_.initial_estimate,
                         this->model_.states());
    this->info_.name = options_.name;
    reset();
  }
  void reset() override {
    x_ = options_.initial_estimate;
    pending_ = false;
    this->reset_clock();
  }

 private:
  // x̂ along the move from x̂_{k−1}: f, plus the last sample's correction on the first move.
  bool predict(long k, const ModelStep& move) {
    Eigen::VectorXd next = advance(this->model_, State(x_), this->held_input(), move);
    if (pending_) next += correction_;
    pending_ = false;
    return accept_finite(next, x_, this->step_, this->name(), k);  // an unstable L overflows
  }
  void update(long, const Eigen::VectorXd& y) {
    correction_ = options_.gain * measured_error(this->model_, x_, y);
    pending_ = true;
  }
  const Eigen::VectorXd& estimate() const { return x_; }

  using State = ModelVector<double, Model::kStates>;
  LuenbergerOptions options_;
  Eigen::VectorXd x_, correction_;
  bool pending_ = false;  // correction_ waits for the next sample's first move
};

// x̂⁺ = f(x̂, u, k) + Q e + R sat(e / γ), e = y − h(x̂), sat = clamp to [−1, 1] per entry
// (Q, R: n × p gains; γ > 0 the boundary layer).
template <DiscreteModel Model>
class SlidingModeObserver final
    : public detail::PredictUpdateObserver<Model, SlidingModeObserver<Model>> {
  using Base = detail::PredictUpdateObserver<Model, SlidingModeObserver<Model>>;
  friend Base;

 public:
  SlidingModeObserver(Model model, SlidingModeOptions options)
      : Base(std::move(model), kConstantGain, false),
        options_(detail::validated(std::move(options))) {
    const Eigen::Index n = this->model_.states(), p = this->model_.outputs();
    detail::require_shape("SlidingModeOptions", "q", options_.q, n, p);
    detail::require_shape("SlidingModeOptions", "r", options_.r, n, p);
    detail::require_size("SlidingModeOptions", "initial_estimate", options_.initial_estimate, n);
    this->info_.name = options_.name;
    reset();
  }
  void reset() override {
    x_ = options_.initial_estimate;
    pending_ = false;
    this->reset_clock();
  }

 private:
  bool predict(long k, const ModelStep& move) {
    Eigen::VectorXd next = advance(this->model_, State(x_), this->held_input(), move);
    if (pending_) next += correction_;
    pending_ = false;
    return accept_finite(next, x_, this->step_, this->name(), k);
  }
  void update(long, const Eigen::VectorXd& y) {
    const Eigen::VectorXd e = measured_error(this->model_, x_, y);
    correction_ = options_.q * e + options_.r * (e / options_.gamma).cwiseMax(-1.0).cwiseMin(1.0);
    pending_ = true;
  }
  const Eigen::VectorXd& estimate() const { return x_; }

  using State = ModelVector<double, Model::kStates>;
  SlidingModeOptions options_;
  Eigen::VectorXd x_, correction_;
  bool pending_ = false;
};

// Extended Kalman filter with Jacobians of f and h by forward-mode AD (ceres::Jet). At sample k,
// first predict from the last sample's time along each move of the model (SampleClock: one
// step T each, or the flow over an interval off the grid, Q weighted by its length / T):
//   x̂ ← f(x̂, u_{k−1}),  P ← F P Fᵀ + w Q;
// then update with the outputs measured at k (H, R and y restricted to them):
//   K = P Hᵀ (H P Hᵀ + R)⁻¹, x̂ ← x̂ + K (y − h(x̂)), P ← (I − K H) P (I − K H)ᵀ + K R Kᵀ
// (Joseph's form [BJ68]: a sum of positive semi-definite terms whatever K's rounding),
// and report x̂_k. A second sample at the same instant is a second update.
// Cost per sample with n states and p outputs: the update is O(n² p) (I − K H is never formed);
// the prediction O(n³) with a dense F, O(nnz(F) n) with the sparse F a model of run-time size
// n ≥ 100 gets (move_covariance.hpp: a traced pattern and compressed AD, or the dense F's
// exact nonzeros). P is dense n × n: memory O(n²).
// An update or prediction that is not finite is not taken (the step says so): the estimate
// keeps its last finite value, and a non-finite predicted covariance restarts from P0.
struct EkfOptions {
  std::string name = "ekf";                // in reports
  Eigen::VectorXd initial_estimate;        // x̂_0: n finite numbers (required)
  Eigen::MatrixXd process_covariance;      // Q (n × n); empty: 1e-6 I
  Eigen::MatrixXd measurement_covariance;  // R (p × p); empty: 1e-4 I
  Eigen::MatrixXd initial_covariance;      // P0 (n × n); empty: I
  // Run-time n ≥ 100: F sparse where the model allows (move_covariance.hpp); false: F dense and
  // F P Fᵀ by dense products at every size (the same numbers up to rounding).
  bool sparse_jacobian = true;
  // Throws InvalidInput naming the field: an empty name, an initial estimate that is empty or
  // not finite, a covariance given but not square, finite, symmetric positive semi-definite.
  void validate() const;
};

template <DiscreteModel Model>
class ExtendedKalmanFilter final
    : public detail::PredictUpdateObserver<Model, ExtendedKalmanFilter<Model>> {
  using Base = detail::PredictUpdateObserver<Model, ExtendedKalmanFilter<Model>>;
  friend Base;
  using Base::model_;
  using Base::step_;

 public:
  ExtendedKalmanFilter(Model model, EkfOptions options)
      : Base(std::move(model), "", true),
        initial_(options.initial_estimate),
        propagation_(options.sparse_jacobian) {
    options.validate();
    this->info_.name = options.name;
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
    this->reset_clock();
  }

  // How the last prediction formed F P Fᵀ: "dense", or the sparse path and its pattern (or why
  // it was declined): move_covariance.hpp.
  const std::string& jacobian_note() const { return propagation_.note(); }

 private:
  using State = ModelVector<double, Model::kStates>;
  using Input = ModelVector<double, Model::kInputs>;

  // x̂ ← f(x̂, u_{k−1}), P ← F P Fᵀ + w Q along one move; false when it was not taken.
  bool predict(long k, const ModelStep& move) {
    const State x(x_);
    const Input u = this->held_input();
    propagation_.propagate(model_, x, u, move, p_, q_, covariance_);
    const Eigen::VectorXd predicted = advance(model_, x, u, move);
    if (!accept_finite(predicted, x_, step_, this->name(), k, "the predicted state")) return false;
    if (covariance_.allFinite()) {
      p_.swap(covariance_);
      return true;
    }
    predicted_failure(k, "the predicted covariance P", "P restarts from P0");
    p_ = p0_;  // so that the filter can re-acquire; the state moved, so the next moves go on
    return true;
  }

  // The update with the outputs measured in y (all of them, or the finite entries).
  void update(long k, const Eigen::VectorXd& y) {
    if (step_.measurement_missing) return;
    Matrix<Model::kOutputs, Model::kStates> jac;
    output_jacobian(model_, State(x_), jac);
    Eigen::MatrixXd hj = jac, r = r_;
    Eigen::VectorXd innovation = y - Eigen::VectorXd(model_.h(State(x_)));
    if (!y.allFinite()) {
      const std::vector<Eigen::Index> rows = measured_outputs(y);
      hj = Eigen::MatrixXd(hj(rows, Eigen::all));
      r = Eigen::MatrixXd(r_(rows, rows));
      innovation = Eigen::VectorXd(innovation(rows));
    }
    const Eigen::MatrixXd pht = p_ * hj.transpose();  // P Hᵀ, n × p
    const Eigen::MatrixXd s = hj * pht + r;
    const Eigen::MatrixXd gain = pht * s.inverse();
    const Eigen::VectorXd updated = x_ + gain * innovation;
    // Joseph's form in O(n² p): B = (I − K H) P = P − K (H P), then
    // P⁺ = B (I − K H)ᵀ + K R Kᵀ = B − (B Hᵀ) Kᵀ + K R Kᵀ.
    covariance_ = p_;
    covariance_.noalias() -= gain * (hj * p_);
    const Eigen::MatrixXd bht = covariance_ * hj.transpose();
    covariance_.noalias() -= bht * gain.transpose();
    covariance_.noalias() += gain * r * gain.transpose();
    if (updated.allFinite() && covariance_.allFinite()) {
      x_ = updated;
      p_.swap(covariance_);
    } else {
      predicted_failure(k, "the measurement update", "kept the last finite estimate");
    }
  }

  void predicted_failure(long k, const char* what, const char* action) {
    std::ostringstream os;
    os << this->name() << ": " << what << " at sample k = " << k << " is not finite; " << action;
    mark_non_finite_estimate(step_, os.str());
  }

  const Eigen::VectorXd& estimate() const { return x_; }

  Eigen::VectorXd initial_, x_;
  Eigen::MatrixXd q_, r_, p0_, p_, covariance_;
  detail::MoveCovariance<Model> propagation_;
};

}  // namespace nlobs
