#pragma once
// The naive baseline for derivative estimation: for a system whose state is the output's phase
// variables x = (y, y', …, y⁽ⁿ⁻¹⁾), x̂_{i+1} = ∇ⁱ y_k / δⁱ (backward differences of the samples).
// Its noise gain grows as 1/δⁱ — what the modulating-function observer's integration avoids.
#include <Eigen/Core>
#include <cmath>
#include <optional>
#include <string>

#include "nlobs/observers/core/observer.hpp"
#include "nlobs/observers/core/option_checks.hpp"
#include "nlobs/observers/core/sampled_data.hpp"

namespace nlobs {

// It needs no model (x is y's phase variables by assumption), so its options are all it takes.
struct FiniteDifferenceOptions {
  std::string name = "finite_difference";  // in reports
  Eigen::Index states = 0;   // n ≥ 1: x̂ = (y, y', …, y⁽ⁿ⁻¹⁾) (required)
  double sample_time = 0.0;  // δ > 0 between samples (required)
  // Throws InvalidInput naming the field and value: an empty name, n < 1, δ not finite and > 0.
  void validate() const {
    detail::require_name("FiniteDifferenceOptions", name);
    detail::require_at_least("FiniteDifferenceOptions", "states", static_cast<long>(states), 1L);
    detail::require_positive("FiniteDifferenceOptions", "sample_time", sample_time);
  }
};

// Samples are placed by their time on the uniform grid t_0 + m·δ (UniformGrid: off the grid is
// the failure "non_uniform"): the differences divide by δ, so a sample off the grid, a missing
// one and a skipped grid point (a dropped row) restart them.
class FiniteDifferenceObserver final : public Observer {
 public:
  explicit FiniteDifferenceObserver(FiniteDifferenceOptions options)
      : options_(detail::validated(std::move(options))), grid_(options_.sample_time) {
    const Eigen::Index n = options_.states;
    history_.resize(n);
    differences_.resize(n);
    estimate_.resize(n);
    info_.name = options_.name;
    info_.window = n;
    reset();
  }

  void reset() override {
    grid_.reset();
    history_.setZero();
    filled_ = 0;
    last_index_ = -1;
    step_.estimate = Eigen::VectorXd::Zero(options_.states);
    step_.ready = false;
    step_.failure.clear();
    step_.failure_message.clear();
  }
  const ObserverStep& step(long k, double t, const Eigen::VectorXd& y,
                           const Eigen::VectorXd&) override {
    const Eigen::Index n = options_.states;
    step_.failure.clear();
    step_.failure_message.clear();
    step_.measurement_missing = false;
    const std::optional<GridPoint> point = grid_.place(options_.name, k, t, step_);
    if (point) step_.measurement_missing = !(y.size() == 1 && std::isfinite(y[0]));
    if (!point || step_.measurement_missing || point->index != last_index_ + 1) {
      filled_ = 0;  // the differences restart after a gap
    }
    if (point) last_index_ = point->index;
    if (!point || step_.measurement_missing) {
      step_.ready = false;
      return step_;
    }
    for (Eigen::Index i = n - 1; i > 0; --i) history_[i] = history_[i - 1];
    history_[0] = y[0];  // newest first
    if (filled_ < n) ++filled_;
    step_.ready = filled_ == n;
    if (!step_.ready) return step_;
    // ∇ⁱ y_k from the newest n samples: repeated differences, newest first.
    differences_ = history_;
    double scale = 1.0;
    estimate_[0] = differences_[0];
    for (Eigen::Index i = 1; i < n; ++i) {
      for (Eigen::Index m = 0; m + i < n; ++m) differences_[m] -= differences_[m + 1];
      scale *= options_.sample_time;
      estimate_[i] = differences_[0] / scale;
    }
    accept_finite(estimate_, step_.estimate, step_, options_.name, k, "the differences");  // huge y
    return step_;
  }

 private:
  FiniteDifferenceOptions options_;
  UniformGrid grid_;
  Eigen::VectorXd history_, differences_, estimate_;
  Eigen::Index filled_ = 0;
  long last_index_ = -1;  // the grid index of the last sample placed
  ObserverStep step_;
};

}  // namespace nlobs
