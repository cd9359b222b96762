#pragma once
// Applies StopCriteria to the sequence of step norms an engine produces. Shared by every
// engine so that the criteria mean the same thing everywhere. No allocation, no division
// by zero: ratios are formed only from non-zero steps.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "nlobs/solvers/stop_criteria.hpp"
#include "nlobs/solvers/summary.hpp"

namespace nlobs {

class StopMonitor {
 public:
  // estimate_lipschitz: the engine's steps are Picard steps x_{l+1} = G(x_l), so their ratio
  // estimates the contraction factor of G. Other engines' step ratios measure their own
  // convergence, not G's Lipschitz constant, and must not feed an error bound.
  // progress: what stagnation and divergence are judged by — the steps (monotone methods: the
  // paper's rule, StopCriteria::stagnation_patience) or the best residual over a window
  // (non-monotone methods such as Anderson: StopCriteria::residual_window).
  enum class Progress { kSteps, kBestResidual };
  StopMonitor(const StopCriteria& criteria, double x0_norm, bool estimate_lipschitz,
              Progress progress = Progress::kSteps)
      : c_(criteria),
        limit_(criteria.divergence_limit * std::max(1.0, x0_norm)),
        estimate_lipschitz_(estimate_lipschitz),
        progress_(progress) {}

  // After each completed iteration: the step ‖x_l − x_{l−1}‖∞, the residual ‖G − x‖∞ at the
  // last evaluated point (NaN when unknown) and ‖x_l‖∞. Returns the final status or nullopt.
  // step_may_converge = false: the step was cut short by the engine (a trust region's radius),
  // so its smallness says nothing about the distance to a root; the step criterion is not
  // applied to it (the residual criterion still is).
  std::optional<Status> update(double step, double residual, double iterate_norm,
                               bool step_may_converge = true) {
    ++iterations_;
    last_step_ = step;
    if (prev_step_ > 0.0) {
      ratios_[ratio_count_ % kRatios] = step / prev_step_;
      ++ratio_count_;
    }
    if (iterate_norm > limit_) return Status::kDiverged;
    if (converged(step_may_converge ? step : std::numeric_limits<double>::infinity(), residual)) {
      return Status::kConverged;
    }

    zero_steps_ = (step == 0.0) ? zero_steps_ + 1 : 0;
    if (c_.stop_on_repeated_iterates && zero_steps_ >= 2) {
      return Status::kRepeatedIterates;  // x_l = x_{l−1} = x_{l−2}
    }
    if (progress_ == Progress::kBestResidual) {
      if (residual < best_residual_) {  // (NaN: no record)
        best_residual_ = residual;
        since_best_ = 0;
        far_above_ = 0;
      } else {
        ++since_best_;
        far_above_ = residual > c_.divergence_growth * best_residual_ ? far_above_ + 1 : 0;
      }
      if (c_.residual_window > 0) {
        if (far_above_ >= c_.residual_window) return Status::kDiverged;
        if (since_best_ >= c_.residual_window) return Status::kStagnated;
      }
    } else if (iterations_ > 1 && step >= prev_step_) {
      if (non_shrinking_ == 0) run_start_step_ = prev_step_;
      ++non_shrinking_;
      if (c_.stagnation_patience > 0 && non_shrinking_ >= c_.stagnation_patience) {
        const bool grew =
            run_start_step_ > 0.0 ? step > c_.divergence_growth * run_start_step_ : step > 0.0;
        return grew ? Status::kDiverged : Status::kStagnated;
      }
    } else {
      non_shrinking_ = 0;
    }
    if (iterations_ >= c_.max_iterations) return Status::kMaxIterations;
    prev_step_ = step;
    return std::nullopt;
  }

  int iterations() const { return iterations_; }

  // Last ratio of consecutive steps: the observed linear convergence factor.
  std::optional<double> contraction_estimate() const {
    if (ratio_count_ == 0) return std::nullopt;
    return ratios_[(ratio_count_ - 1) % kRatios];
  }

  // The Lipschitz constant for bounds: given, or the largest of the last few step ratios
  // when at least two are known and all are < 1.
  std::optional<double> lipschitz(bool* estimated) const {
    *estimated = false;
    if (c_.lipschitz_constant) return c_.lipschitz_constant;
    if (!estimate_lipschitz_ || ratio_count_ < 2) return std::nullopt;
    const int k = std::min(ratio_count_, kRatios);
    const double l = *std::max_element(ratios_, ratios_ + k);
    if (!(l < 1.0)) return std::nullopt;
    *estimated = true;
    return l;
  }

  // Copies step, contraction, L, the error bound for `residual` at the returned point and
  // the a priori iteration count into the summary.
  void fill(Summary& s, double residual) const {
    s.iterations = iterations_;
    s.step_norm = last_step_;
    s.residual_norm = residual;
    s.contraction_estimate = contraction_estimate();
    bool estimated = false;
    s.lipschitz_constant = lipschitz(&estimated);
    s.lipschitz_is_estimate = estimated;
    if (s.lipschitz_constant && std::isfinite(residual)) {
      s.error_bound = residual / (1.0 - *s.lipschitz_constant);  // ‖x − p‖ ≤ ‖G(x) − x‖/(1−L)
    }
    const std::optional<double> tol = c_.error_tolerance ? c_.error_tolerance : c_.step_tolerance;
    if (s.lipschitz_constant && tol && *tol < 1.0) {
      const double m = -std::log10(*tol);
      const double l = *s.lipschitz_constant;
      s.a_priori_iterations =
          l > 0.0 ? static_cast<int>(std::ceil(m / std::log10(1.0 / l))) : 1;  // eq. (64)
    }
  }

 private:
  static constexpr int kRatios = 3;

  bool converged(double step, double residual) const {
    int enabled = 0, met = 0;
    auto test = [&](bool on, bool ok) {
      enabled += on;
      met += on && ok;
    };
    test(c_.step_tolerance.has_value(), c_.step_tolerance && step <= *c_.step_tolerance);
    test(c_.residual_tolerance.has_value(),
         c_.residual_tolerance && residual <= *c_.residual_tolerance);  // NaN: false
    if (c_.error_tolerance) {
      bool estimated = false;
      const std::optional<double> l = lipschitz(&estimated);
      test(true, l && step <= (1.0 - *l) * *c_.error_tolerance);  // Remark 6, eq. (65)
    }
    if (enabled == 0) return false;
    return c_.combine == Combine::kAny ? met > 0 : met == enabled;
  }

  StopCriteria c_;
  double limit_;
  bool estimate_lipschitz_;
  Progress progress_;
  double best_residual_ = std::numeric_limits<double>::infinity();
  int since_best_ = 0, far_above_ = 0;  // iterations since the best residual; run above growth×
  int iterations_ = 0;
  double prev_step_ = 0.0;
  double last_step_ = 0.0;
  double run_start_step_ = 0.0;
  int non_shrinking_ = 0;
  int zero_steps_ = 0;
  double ratios_[kRatios] = {0.0, 0.0, 0.0};
  int ratio_count_ = 0;
};

}  // namespace nlobs
