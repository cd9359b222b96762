#pragma once
// Unscented Kalman filter ([JU97]) with the scaled sigma points and weights of [WvdM00], for any
// discrete model x⁺ = f(x, u, k), y = h(x) — a baseline beside the EKF that needs no Jacobian:
//   λ = α²(n + κ) − n,  χ_0 = x̂,  χ_{±i} = x̂ ± (L)_i,  L Lᵀ = (n + λ) P  (Cholesky),
//   W_0^m = λ/(n + λ),  W_0^c = W_0^m + 1 − α² + β,  W_{±i} = 1/(2(n + λ)).
// At sample k, first predict from the last sample's time along each move of the model
// (SampleClock: one step T each, or the flow over an interval off the grid, Q weighted by its
// length / T): χ_i ← f(χ_i, u_{k−1}), x̂ = Σ W^m χ_i, P = Σ W^c (χ_i − x̂)(..)ᵀ + w Q;
// then update with the outputs measured at k (h, R and y restricted to them):
//   Y_i = h(χ_i), ŷ = Σ W^m Y_i, S = Σ W^c (Y_i − ŷ)(Y_i − ŷ)ᵀ + R,
//   C = Σ W^c (χ_i − x̂)(Y_i − ŷ)ᵀ, K = C S⁻¹, x̂ ← x̂ + K (y − ŷ), P ← P − K S Kᵀ;
// and report x̂_k. On a linear model it is the Kalman filter (tested).
// Cost per sample with n states: 2n + 1 moves of the model, a Cholesky factor (n³/3) and the
// weighted sums as matrix products (2n³): O(n³) whatever F's structure, memory O(n²).
//
// A P that the Cholesky factorisation refuses (rounding, or a negative W_0^c with α < 1) is
// repaired, never thrown about: symmetrised, then its diagonal raised by
// δ = 1e-12 · max(1, max_i |P_ii|), ten times more per try, up to 10 tries (covariance_repairs()
// counts them). When that fails, or a step is not finite, the step is not taken: x̂ keeps its
// last finite value, P restarts from P0, and the step says so (failure non_finite_estimate).
// A sample's non-finite entries are outputs not measured; measurement_missing when none is.
#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "nlobs/models/model.hpp"
#include "nlobs/observers/core/observer.hpp"
#include "nlobs/observers/core/option_checks.hpp"
#include "nlobs/observers/core/predict_update_observer.hpp"

namespace nlobs {

struct UkfOptions {
  std::string name = "ukf";                // in reports
  Eigen::VectorXd initial_estimate;        // x̂_0: n finite numbers (required)
  Eigen::MatrixXd process_covariance;      // Q (n × n); empty: 1e-6 I
  Eigen::MatrixXd measurement_covariance;  // R (p × p); empty: 1e-4 I
  Eigen::MatrixXd initial_covariance;      // P0 (n × n); empty: I
  // The spread of the sigma points, α ∈ (0, 1]; the default 1 with κ = 0 gives λ = 0: no
  // negative weight, the most robust choice ([WvdM00] suggest α = 1e-3 for a tighter spread).
  double alpha = 1.0;
  double beta = 2.0;   // prior knowledge of the distribution; 2 is optimal for a Gaussian; ≥ 0
  double kappa = 0.0;  // secondary scaling; n + λ must stay > 0
  // Throws InvalidInput naming the field: as EkfOptions, and α ∉ (0, 1], β < 0, κ not finite.
  void validate() const;
};

template <DiscreteModel Model>
class UnscentedKalmanFilter final
    : public detail::PredictUpdateObserver<Model, UnscentedKalmanFilter<Model>> {
  using Base = detail::PredictUpdateObserver<Model, UnscentedKalmanFilter<Model>>;
  friend Base;
  using Base::model_;
  using Base::step_;

 public:
  UnscentedKalmanFilter(Model model, UkfOptions options)
      : Base(std::move(model), "", true), options_(detail::validated(std::move(options))) {
    this->info_.name = options_.name;
    const Eigen::Index n = model_.states(), p = model_.outputs();
    const detail::Covariances c = detail::covariances_of("UkfOptions", options_, n, p);
    q_ = c.process;
    r_ = c.measurement;
    p0_ = c.initial;
    detail::require_size("UkfOptions", "initial_estimate", options_.initial_estimate, n);
    const double dn = static_cast<double>(n);
    lambda_ = options_.alpha * options_.alpha * (dn + options_.kappa) - dn;
    if (!(dn + lambda_ > 0.0)) {
      std::ostringstream got;
      got << options_.kappa << " (n + lambda = " << dn + lambda_ << ")";
      detail::invalid_option("UkfOptions", "kappa", "give n + lambda > 0", got.str());
    }
    wm0_ = lambda_ / (dn + lambda_);
    wc0_ = wm0_ + 1.0 - options_.alpha * options_.alpha + options_.beta;
    wi_ = 0.5 / (dn + lambda_);
    reset();
  }

  void reset() override {
    x_ = options_.initial_estimate;
    p_ = p0_;
    repairs_ = 0;
    this->reset_clock();
  }

  // How many times P was repaired (symmetrised and its diagonal raised) since reset().
  int covariance_repairs() const { return repairs_; }

 private:
  using State = ModelVector<double, Model::kStates>;

  // The sigma points through one move; false when the step was not taken.
  bool predict(long k, const ModelStep& move) {
    const Eigen::Index n = model_.states();
    if (!sigma_points(k, "the prediction")) return false;
    const ModelVector<double, Model::kInputs> u = this->held_input();
    for (Eigen::Index i = 0; i < 2 * n + 1; ++i) {
      chi_.col(i) = Eigen::VectorXd(advance(model_, State(chi_.col(i)), u, move));
    }
    const Eigen::VectorXd predicted = mean(chi_);
    Eigen::MatrixXd covariance = move.weight * q_;
    spread_ = chi_.colwise() - predicted;
    add_weighted_product(spread_, spread_, covariance);
    if (predicted.allFinite() && covariance.allFinite()) {
      x_ = predicted;
      p_ = 0.5 * (covariance + covariance.transpose());
      return true;
    }
    fail(k, "the prediction", "kept the last finite estimate; P restarts from P0");
    p_ = p0_;
    return false;
  }

  // The update with the outputs measured in y (all of them, or the finite entries).
  void update(long k, const Eigen::VectorXd& y) {
    if (step_.measurement_missing) return;
    const Eigen::Index n = model_.states();
    if (!sigma_points(k, "the measurement update")) return;
    std::vector<Eigen::Index> rows;
    if (!y.allFinite()) rows = measured_outputs(y);
    const Eigen::Index p = rows.empty() ? model_.outputs() : static_cast<Eigen::Index>(rows.size());
    ys_.resize(p, 2 * n + 1);
    for (Eigen::Index i = 0; i < 2 * n + 1; ++i) {
      const Eigen::VectorXd yi = model_.h(State(chi_.col(i)));
      if (rows.empty()) {
        ys_.col(i) = yi;
      } else {
        ys_.col(i) = yi(rows);
      }
    }
    const Eigen::VectorXd y_mean = mean(ys_);
    Eigen::MatrixXd s = rows.empty() ? r_ : Eigen::MatrixXd(r_(rows, rows));
    Eigen::MatrixXd c = Eigen::MatrixXd::Zero(n, p);
    ys_.colwise() -= y_mean;
    spread_ = chi_.colwise() - x_;
    add_weighted_product(ys_, ys_, s);
    add_weighted_product(spread_, ys_, c);
    const Eigen::VectorXd measured = rows.empty() ? y : Eigen::VectorXd(y(rows));
    const Eigen::PartialPivLU<Eigen::MatrixXd> lu(s);
    const Eigen::MatrixXd gain = lu.solve(c.transpose()).transpose();  // C S⁻¹ (S symmetric)
    const Eigen::VectorXd updated = x_ + gain * (measured - y_mean);
    Eigen::MatrixXd covariance = p_ - gain * s * gain.transpose();
    covariance = 0.5 * (covariance + covariance.transpose());
    if (updated.allFinite() && covariance.allFinite()) {
      x_ = updated;
      p_ = covariance;
    } else {
      fail(k, "the measurement update", "kept the last finite estimate");
    }
  }

  // χ = [x̂, x̂ + L, x̂ − L] from the Cholesky factor of (n + λ) P, repaired if need be; false
  // (P restarted from P0, the step marked) when no repair gives a factor.
  bool sigma_points(long k, const char* where) {
    const Eigen::Index n = model_.states();
    p_ = 0.5 * (p_ + p_.transpose());
    Eigen::LLT<Eigen::MatrixXd> llt(p_);
    if (llt.info() != Eigen::Success && p_.allFinite()) {
      double jitter = 1e-12 * std::max(1.0, p_.diagonal().cwiseAbs().maxCoeff());
      for (int attempt = 0; attempt < 10 && llt.info() != Eigen::Success; ++attempt) {
        Eigen::MatrixXd raised = p_;
        raised.diagonal().array() += jitter;
        llt.compute(raised);
        if (llt.info() == Eigen::Success) {
          p_ = raised;
          ++repairs_;
        }
        jitter *= 10.0;
      }
    }
    if (llt.info() != Eigen::Success) {
      std::ostringstream what;
      what << "the covariance P before " << where;
      fail(k, what.str().c_str(), "P restarts from P0");
      p_ = p0_;
      return false;
    }
    const Eigen::MatrixXd spread =
        std::sqrt(static_cast<double>(n) + lambda_) * Eigen::MatrixXd(llt.matrixL());
    chi_.resize(n, 2 * n + 1);
    chi_.col(0) = x_;
    for (Eigen::Index i = 0; i < n; ++i) {
      chi_.col(1 + i) = x_ + spread.col(i);
      chi_.col(1 + n + i) = x_ - spread.col(i);
    }
    return true;
  }

  // out += Σ_i W^c_i a_i b_iᵀ over the sigma points' columns, as one matrix product (the O(n³)
  // of the prediction's covariance, blocked, rather than 2n + 1 outer products).
  void add_weighted_product(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b,
                            Eigen::MatrixXd& out) {
    weighted_ = a;
    weighted_.col(0) *= wc0_;
    weighted_.rightCols(weighted_.cols() - 1) *= wi_;
    out.noalias() += weighted_ * b.transpose();
  }

  Eigen::VectorXd mean(const Eigen::MatrixXd& points) const {
    return wm0_ * points.col(0) + wi_ * points.rightCols(points.cols() - 1).rowwise().sum();
  }

  void fail(long k, const char* what, const char* action) {
    std::ostringstream os;
    os << this->name() << ": " << what << " at sample k = " << k
       << " is not finite or not positive "
       << "definite; " << action;
    mark_non_finite_estimate(step_, os.str());
  }

  const Eigen::VectorXd& estimate() const { return x_; }

  UkfOptions options_;
  double lambda_ = 0.0, wm0_ = 0.0, wc0_ = 0.0, wi_ = 0.0;
  Eigen::VectorXd x_;
  Eigen::MatrixXd q_, r_, p0_, p_, chi_, ys_, spread_, weighted_;
  int repairs_ = 0;
};

}  // namespace nlobs
