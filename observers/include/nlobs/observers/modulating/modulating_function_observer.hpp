#pragma once
// Modulating-function algebraic observer ([MF-LTV]; derivation in
// docs/observers.md). For a form (modulating_forms.hpp) with g_i = a_i y − b_iᵀ v (g_n = y),
// integrating the input–output equation against the unitary kernel φ_j by parts leaves
//   η_j(t) = (−1)^{j+1} Σ_{i=0}^{n} (−1)^i ∫_{t−T}^{t} φ_j⁽ⁱ⁾(τ − t + T) g_i(τ) dτ,
// exact after one horizon T. On uniformly sampled data each integral is an FIR filter: the
// weights K_{j,i}[m] = (−1)^{i+j+1} w_m φ_j⁽ⁱ⁾(m δ) (trapezoid or Simpson w_m) are computed once
// and the channels g_i(τ_m) (coefficients evaluated on the grid as the samples arrive) are
// kept in ring buffers — a step is n(n+1) dot products of length T/δ + 1 and allocates nothing.
//
// Sampled-data mode (sample_period h = M δ): outputs arrive every h; between them the output
// predictor ŷ' = η̂_{n−2} − a_{n−1}(t) ŷ + b_{n−1}ᵀ v(t, ŷ, u) (the copy of the output's own
// equation driven by the estimate), reset to y at each sample, fills the grid (Heun's method
// with η̂ extrapolated over one δ). Before the first horizon the predictor runs on the initial
// guess (the paper's constant initial function).
//
// Built as ModulatingFunctionObserver(form, ModulatingOptions) like every observer: the options
// hold the name, x̂(0) and the design; ModulatingOptions::validate() (called by the constructor)
// checks what the options alone can tell, the constructor the sizes against the form.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "nlobs/models/modulating_forms.hpp"
#include "nlobs/observers/core/observer.hpp"
#include "nlobs/observers/core/option_checks.hpp"
#include "nlobs/observers/core/sampled_data.hpp"
#include "nlobs/observers/modulating/modulating_kernel.hpp"
#include "nlobs/solvers/status.hpp"

namespace nlobs {

enum class Quadrature { kTrapezoid, kSimpson };

struct ModulatingOptions {
  std::string name = "modulating";     // in reports
  Eigen::VectorXd initial_estimate{};  // x̂(0): the guess for the state, finite (required)
  double sample_time = 0.0;  // δ: the spacing of the samples the observer is stepped with
  double horizon = 1.0;      // T: a multiple of δ, at least 4 intervals
  Quadrature quadrature = Quadrature::kSimpson;  // Simpson needs an even number of intervals
  ModulatingKernelOptions kernel{};
  // Sampled-data mode: outputs every h = M δ (M ≥ 1 integer), the predictor between; 0: FIR
  // mode, every sample is a measurement.
  double sample_period = 0.0;
  // FIR mode, times off the grid t_0 + m δ: interpolate linearly onto the grid (true) or refuse
  // the sample (false: failure "non_uniform", state kept).
  bool resample = false;
  // With resample: spans between samples up to this are interpolated; longer ones are gaps
  // (their grid points missing). 0 means 4 δ.
  double resample_max_gap = 0.0;
  // Theorem 1's bound on |η_j − η̂_j| when an unknown d with |d| ≤ disturbance_level enters
  // η' as disturbance_gains · d (FIR mode; empty: no bound).
  Eigen::VectorXd disturbance_gains{};
  double disturbance_level = 0.0;
  // Throws InvalidInput naming the field and its value: an empty name; an initial estimate
  // that is empty or not finite; δ or T not finite and positive; T not a multiple of δ, shorter
  // than 4 intervals, or an odd count of them with Simpson; h neither 0 nor a positive multiple
  // of δ; a resample gap neither 0 nor finite and ≥ δ; a disturbance level not finite and ≥ 0;
  // disturbance gains given but not finite. The kernel options need n: the kernel design
  // checks them (modulating_kernel.hpp), the sizes the constructor.
  void validate() const;
};

template <typename Form>
class ModulatingFunctionObserver final : public Observer {
 public:
  static constexpr int n = Form::n, p = Form::p, nx = Form::state_size;
  using Eta = Vector<n>;
  using State = Vector<nx>;

  // `kernel_engine` solves the noise-optimal kernel design (ModulatingKernels; none given:
  // Ceres), once, here. Throws InvalidInput naming the field: ModulatingOptions::validate()'s
  // checks, the kernel options (modulating_kernel.hpp), an initial estimate of other than
  // Form::state_size entries or disturbance gains of other than n.
  ModulatingFunctionObserver(Form form, ModulatingOptions options,
                             std::unique_ptr<Engine<Eigen::Dynamic>> kernel_engine = nullptr)
      : form_(std::move(form)),
        options_(detail::validated(std::move(options))),
        kernels_(make_kernels(std::move(kernel_engine))) {
    detail::require_size("ModulatingOptions", "initial_estimate", options_.initial_estimate, nx);
    if (options_.disturbance_gains.size() != 0 && options_.disturbance_gains.size() != n) {
      detail::invalid_option("ModulatingOptions", "disturbance_gains",
                             "have n = " + std::to_string(n) + " entries, or none (no bound)",
                             std::to_string(options_.disturbance_gains.size()));
    }
    initial_ = options_.initial_estimate;
    eta_guess_ = form_.canonical(0.0, initial_);
    const double delta = options_.sample_time;
    // validate() checked that h is 0 or a whole number of δ, and the gap 0 or at least δ.
    if (options_.sample_period != 0.0) every_ = std::lround(options_.sample_period / delta);
    max_gap_ = options_.resample_max_gap == 0.0 ? 4.0 * delta : options_.resample_max_gap;
    // K_{j,i}[m] = (−1)^{i+j+1} w_m φ_j⁽ⁱ⁾(m δ), column j(n+1)+i, m oldest (t − T) to newest.
    weights_.resize(L_ + 1, n * (n + 1));
    for (Eigen::Index m = 0; m <= L_; ++m) {
      double w = delta;
      if (options_.quadrature == Quadrature::kTrapezoid) {
        if (m == 0 || m == L_) w = delta / 2.0;
      } else {
        w = (m == 0 || m == L_) ? delta / 3.0 : (m % 2 ? 4.0 * delta / 3.0 : 2.0 * delta / 3.0);
      }
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i <= n; ++i) {
          const double sign = (i + j + 1) % 2 ? -1.0 : 1.0;
          weights_(m, j * (n + 1) + i) =
              sign * w * kernels_.value(j, i, static_cast<double>(m) * delta);
        }
      }
    }
    bound_ = Eta::Constant(std::numeric_limits<double>::quiet_NaN());
    if (options_.disturbance_gains.size() != 0 && every_ == 0) {
      // d enters g_i as −gains_i d: |η_j − η̂_j| ≤ D Σ_m |Σ_i K_{j,i}[m] gains_i|.
      for (int j = 0; j < n; ++j) {
        Eigen::VectorXd k = Eigen::VectorXd::Zero(L_ + 1);
        for (int i = 0; i < n; ++i) {
          k += options_.disturbance_gains[i] * weights_.col(j * (n + 1) + i);
        }
        bound_[j] = options_.disturbance_level * k.cwiseAbs().sum();
      }
    }
    channels_.resize(2 * (L_ + 1), n + 1);
    info_.name = options_.name;
    info_.window = L_ + 1;  // the harness's "after the window" is "one horizon after start"
    for (int j = 0; j < n; ++j) {
      info_.signals.push_back({"eta" + std::to_string(j + 1), SignalKind::kCanonicalEstimate});
    }
    info_.signals.push_back({"yhat"});
    if (options_.disturbance_gains.size() != 0) {
      info_.signals.push_back({"eta_bound", SignalKind::kCanonicalBound});
      if (every_ != 0) {
        info_.warnings.push_back(options_.name +
                                 ": the disturbance bound is Theorem 1's (FIR mode); it is not "
                                 "reported in sampled-data mode");
      }
    }
    step_.signals.resize(static_cast<Eigen::Index>(info_.signals.size()));
    reset();
  }

  // η = T(t) x, the canonical state of the true x at t (empty for an x of the wrong size).
  Eigen::VectorXd coordinates_at(const Eigen::VectorXd& x, double t) const override {
    if (x.size() != nx) return {};
    return form_.canonical(t, State(x));
  }

  void reset() override {
    xhat_ = initial_;
    eta_ = eta_guess_;
    eta_previous_ = eta_guess_;
    channels_.setZero();
    write_ = 0;
    filled_ = 0;
    count_ = 0;
    started_ = false;
    yhat_ = eta_guess_[n - 1];
    rate_ = 0.0;
    ever_ready_ = false;
    step_.ready = false;
    step_.measurement_missing = false;
    step_.estimate = initial_;
    step_.signals.setConstant(std::numeric_limits<double>::quiet_NaN());
  }

  // Sample k at t: its grid point comes from t (t_0 + m δ, t_0 the first sample's time), not
  // from k, so that recorded data with gaps and, with `resample`, off-grid times are placed.
  const ObserverStep& step(long k, double t, const Eigen::VectorXd& y,
                           const Eigen::VectorXd& u) override {
    step_.failure.clear();
    step_.failure_message.clear();
    step_.measurement_missing = false;
    if (y.size() != 1) {
      return refuse(k, "input", "y must have one entry (SISO), got " + std::to_string(y.size()));
    }
    if (!std::isfinite(t)) return refuse(k, "non_finite", "the sample time is not finite");
    const double delta = options_.sample_time;
    // Refused before it can anchor the grid: a first sample too large for δ would otherwise
    // put every later one off the grid.
    if (!(grid_tolerance(t, delta) < 0.25)) {  // t's rounding spans the grid step
      return refuse(k, "non_uniform",
                    "t = " + fmt(t) + " is too large for a grid step of " + fmt(delta) +
                        " (its rounding exceeds a quarter step)");
    }
    if (!started_) {
      started_ = true;
      t0_ = t;  // the grid t0 + m δ starts at the first sample
      t_raw_ = t;
      y_raw_ = y[0];
    }
    const double position = (t - t0_) / delta;
    const double grid = std::round(position);
    // sampled_data.hpp's: the rounding of the larger of t and t0
    const double tolerance = grid_tolerance(std::max(std::abs(t), std::abs(t0_)), delta);
    const bool on_grid = std::abs(position - grid) <= tolerance;
    if (count_ > 0 && (!(t > t_raw_) || (on_grid && grid < static_cast<double>(count_)))) {
      return refuse(k, "non_uniform",
                    "sample times must increase by at least one grid step (t = " + fmt(t) +
                        " after " + fmt(t_raw_) + ")");
    }
    const double nan = std::numeric_limits<double>::quiet_NaN();
    if (options_.resample && every_ == 0) {
      // Linear interpolation between the last raw sample and this one at each grid time in
      // (t_raw, t]; a span longer than the gap limit, or a missing y at either end, makes
      // those samples missing.
      const bool bridge = t - t_raw_ <= max_gap_ * (1.0 + 1e-9);
      if (!bridge) {  // every grid time before t is missing: skip them at once
        skip_missing_until(std::floor((t - t0_) / delta + tolerance) - 1.0);
      }
      while (t0_ + static_cast<double>(count_) * delta <= t + tolerance * delta) {
        const double tg = t0_ + static_cast<double>(count_) * delta;
        const double s = std::min(1.0, (tg - t_raw_) / (t - t_raw_));
        const bool at_sample = std::abs(tg - t) <= tolerance * delta;
        advance(tg, at_sample ? y[0] : (bridge ? y_raw_ + s * (y[0] - y_raw_) : nan), u);
      }
    } else if (on_grid) {
      // Skipped grid times are missing samples (the window refills, or the predictor bridges).
      // FIR mode: a gap longer than a horizon empties the window, skipped at once. Sampled-data
      // mode: a gap of more than L + 1 measurement periods is beyond what the predictor
      // bridges: the observer restarts here (absolute time kept), the last estimate kept.
      const double gap = grid - static_cast<double>(count_);
      if (every_ == 0 && gap > static_cast<double>(L_ + 1)) {
        skip_missing_until(grid - 1.0);
      } else if (every_ != 0 && gap > static_cast<double>(every_) * static_cast<double>(L_ + 1)) {
        restart_at(t, y[0]);
        advance(t0_, y[0], u);
        t_raw_ = t;
        y_raw_ = y[0];
        return step_;
      }
      while (static_cast<double>(count_) < grid) {
        advance(t0_ + static_cast<double>(count_) * delta, nan, u);
      }
      advance(t0_ + grid * delta, y[0], u);
    } else {
      return refuse(k, "non_uniform",
                    "t = " + fmt(t) + " is off the uniform grid t0 + m·" + fmt(delta) +
                        " (t0 = " + fmt(t0_) +
                        (every_ != 0 ? "); the sampled-data mode needs the grid"
                                     : "); set resample to interpolate onto the grid"));
    }
    t_raw_ = t;
    y_raw_ = y[0];
    return step_;
  }

  const Eta& eta() const { return eta_; }  // η̂ at the last grid time
  const ModulatingKernels& kernels() const { return kernels_; }
  // Samples per horizon minus one: T = L δ.
  Eigen::Index intervals() const { return L_; }
  // Theorem 1's bound per η_j (NaN without disturbance gains or in sampled-data mode).
  const Eta& disturbance_bound() const { return bound_; }
  // The FIR's gain from white noise on y to η̂_j at time t: ‖Σ_i a_i(τ_m) K_{j,i}[m]‖₂, with
  // the coefficients frozen at t (exact for constant a_i). η̂_j's noise σ is this times σ_y.
  Eta noise_gains(double t = 0.0) const {
    Vector<n> a;
    Matrix<n, p> b;
    form_.coefficients(t, a, b);
    Eta gains;
    for (int j = 0; j < n; ++j) {
      Eigen::VectorXd k = weights_.col(j * (n + 1) + n);
      for (int i = 0; i < n; ++i) k += a[i] * weights_.col(j * (n + 1) + i);
      gains[j] = k.norm();
    }
    return gains;
  }

 private:
  // validate() checked that T is a whole number L ≥ 4 of δ (even for Simpson).
  ModulatingKernels make_kernels(std::unique_ptr<Engine<Eigen::Dynamic>> engine) {
    const double delta = options_.sample_time;
    L_ = std::lround(options_.horizon / delta);
    // Designed on the span the FIR covers (T within 1e-6 of it).
    return ModulatingKernels(n, static_cast<double>(L_) * delta, options_.kernel,
                             std::move(engine));
  }

  // One grid time: a measured output (FIR mode; sampled mode at multiples of h) or the
  // predictor's. NaN: the window is invalid until refilled (FIR) or the predictor bridges it.
  // FIR mode: grid times count_ … last − 1 are all missing, so the window empties once instead
  // of once per grid time: the work of a sample does not grow with the gap before it (a time
  // jump to 1e9 in recorded data). The same state as stepping through them one by one.
  void skip_missing_until(double last) {
    if (!(last > static_cast<double>(count_) + 1.0)) return;
    count_ = static_cast<decltype(count_)>(last);
    step_.measurement_missing = true;
    invalidate("", "");
  }

  // Sampled-data mode after a gap the predictor cannot bridge: a fresh start at t, as at the
  // first sample (the grid is re-anchored at t, so absolute times stay exact), keeping the
  // last estimate published until the window refills.
  void restart_at(double t, double y) {
    const State kept = xhat_;
    reset();
    xhat_ = kept;
    step_.estimate = kept;
    started_ = true;
    t0_ = t;
    t_raw_ = t;
    y_raw_ = y;
    step_.measurement_missing = true;
  }

  void advance(double t, double y, const Eigen::VectorXd& u) {
    const bool measured_now = every_ == 0 || count_ % every_ == 0;
    ++count_;
    coefficients_at(t);
    if (every_ != 0) {
      if (count_ > 1) {  // Heun over δ with η̂ extrapolated: ŷ* = ŷ + δF, ŷ⁺ = ŷ + δ(F + F*)/2
        const double delta = options_.sample_time;
        const double ystar = yhat_ + delta * rate_;
        const Eta extrapolated = 2.0 * eta_ - eta_previous_;
        const double rate_star = predictor_rate(t, ystar, extrapolated, u);
        yhat_ += delta / 2.0 * (rate_ + rate_star);
      }
      if (measured_now && std::isfinite(y)) {
        yhat_ = y;
      } else if (measured_now) {
        step_.measurement_missing = true;
      }
      if (!std::isfinite(yhat_)) {
        invalidate("non_finite", "the output predictor left the finite numbers at t = " + fmt(t));
        yhat_ = eta_guess_[n - 1];
        return;
      }
    } else {
      if (!std::isfinite(y)) {
        step_.measurement_missing = true;
        invalidate("", "");
        return;
      }
      yhat_ = y;
    }
    v_ = form_.inputs(t, yhat_, u);
    if (!v_.allFinite()) {
      invalidate("non_finite", "v(t, y, u) is not finite at t = " + fmt(t));
      return;
    }
    // g_i = a_i y − b_iᵀ v, g_n = y: written twice so that the window is one contiguous block.
    for (int i = 0; i < n; ++i) {
      const double g = a_[i] * yhat_ - b_.row(i).dot(v_);
      channels_(write_, i) = g;
      channels_(write_ + L_ + 1, i) = g;
    }
    channels_(write_, n) = yhat_;
    channels_(write_ + L_ + 1, n) = yhat_;
    write_ = (write_ + 1) % (L_ + 1);
    if (filled_ <= L_) ++filled_;
    eta_previous_ = eta_;
    step_.ready = filled_ == L_ + 1;
    if (step_.ready) {
      for (int j = 0; j < n; ++j) {
        double sum = 0.0;
        for (int i = 0; i <= n; ++i) {
          sum += weights_.col(j * (n + 1) + i).dot(channels_.col(i).segment(write_, L_ + 1));
        }
        eta_[j] = sum;
      }
      // The first estimate replaces the guess: no extrapolation across that jump.
      if (!ever_ready_) eta_previous_ = eta_;
      ever_ready_ = true;
      const State x = form_.state(t, eta_);
      if (x.allFinite()) {
        xhat_ = x;
        step_.estimate = xhat_;
      } else {
        mark_non_finite_estimate(step_, options_.name + ": the state of eta at t = " + fmt(t) +
                                            " is not finite; estimate kept");
      }
    }  // not ready: η̂ stays the guess before the first horizon, the last estimate after
    if (every_ != 0) rate_ = predictor_rate(t, yhat_, eta_, u);
    publish();
  }

  // ŷ' = η̂_{n−2} − a_{n−1}(t) ŷ + b_{n−1}ᵀ v(t, ŷ, u) (η̂_{−1} = 0); a_, b_ hold t's values.
  double predictor_rate(double t, double y, const Eta& eta, const Eigen::VectorXd& u) const {
    const double lower = n >= 2 ? eta[n - 2] : 0.0;
    return lower - a_[n - 1] * y + b_.row(n - 1).dot(form_.inputs(t, y, u));
  }

  void coefficients_at(double t) { form_.coefficients(t, a_, b_); }

  void invalidate(const std::string& failure, const std::string& message) {
    filled_ = 0;
    step_.ready = false;
    if (!failure.empty()) {
      step_.failure = failure;
      step_.failure_message = options_.name + ": " + message + "; the window refills";
    }
    publish();
  }

  void publish() {
    step_.signals.head(n) = eta_;
    step_.signals[n] = yhat_;
    if (options_.disturbance_gains.size() != 0) step_.signals[n + 1] = bound_.norm();
  }

  const ObserverStep& refuse(long k, const std::string& failure, const std::string& message) {
    step_.ready = false;  // the estimate kept is an earlier time's
    step_.failure = failure;
    std::ostringstream os;
    os << options_.name << ": sample " << k << ": " << message << "; estimate kept";
    step_.failure_message = os.str();
    return step_;
  }

  static std::string fmt(double v) {
    std::ostringstream os;
    os.precision(12);
    os << v;
    return os.str();
  }

  Form form_;
  // Before L_ and kernels_: make_kernels() reads the validated options and sets L_.
  ModulatingOptions options_;
  Eigen::Index L_ = 0;
  ModulatingKernels kernels_;
  long every_ = 0;
  double max_gap_ = 0.0;
  Eigen::MatrixXd weights_, channels_;
  Eigen::Index write_ = 0, filled_ = 0;
  long count_ = 0;
  bool started_ = false, ever_ready_ = false;
  double t0_ = 0.0, t_raw_ = 0.0, y_raw_ = 0.0, yhat_ = 0.0, rate_ = 0.0;
  State initial_ = State::Zero(), xhat_ = State::Zero();
  Eta eta_guess_ = Eta::Zero(), eta_ = Eta::Zero(), eta_previous_ = Eta::Zero(),
      bound_ = Eta::Zero();
  Vector<n> a_ = Vector<n>::Zero();
  Matrix<n, p> b_ = Matrix<n, p>::Zero();
  Vector<p> v_ = Vector<p>::Zero();
  ObserverStep step_;
};

}  // namespace nlobs
