#pragma once
// Applies StopCriteria to the sequence of step norms an engine produces. Shared by every
// engine so that the criteria mean the same thing everywhere. No allocation, no division
// by zero: ratios are formed only from non-zero steps.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>

#include "nlobs/solvers/stop_criteria.hpp"
#include "nlobs/solvers/summary.hpp"
#include "nlobs/solvers/types.hpp"

namespace nlobs {

class StopMonitor {
 public:
  // estimate_lipschitz: the engine's steps are Picard steps x_{l+1} = G(x_l), so their ratio
  // estimates the contraction factor of G. Other engines' step ratios measure their own
  // convergence, not G's Lipschitz constant, and must not feed an error bound.
  // progress: what stagnation and divergence are judged by — the steps together with the
  // residual (monotone methods: StopCriteria::stagnation_patience; a run of non-shrinking steps
  // over which ‖F‖ fell is no verdict) or the best residual over a window (non-monotone methods
  // such as Anderson: StopCriteria::residual_window). Both end at the rounding floor
  // (Status::kRoundingFloor).
  // unknowns: n, which sets the residual window in force (StopCriteria::
  // residual_window_per_unknown); 0 when unknown.
  enum class Progress { kSteps, kBestResidual };
  StopMonitor(const StopCriteria& criteria, double x0_norm, bool estimate_lipschitz,
              Progress progress = Progress::kSteps, Index unknowns = 0)
      : c_(criteria),
        limit_(criteria.divergence_limit * std::max(1.0, x0_norm)),
        estimate_lipschitz_(estimate_lipschitz),
        progress_(progress),
        residual_window_(residual_window_for(criteria, unknowns)) {}

  static long residual_window_for(const StopCriteria& c, Index unknowns) {
    if (c.residual_window <= 0) return 0;
    const double scaled = std::ceil(c.residual_window_per_unknown * static_cast<double>(unknowns));
    // Capped where no run could reach it (and a long cannot overflow).
    return static_cast<long>(
        std::max(static_cast<double>(c.residual_window), std::min(scaled, 1e15)));
  }
  // The residual window in force (0: off).
  long residual_window() const { return residual_window_; }

  // After each completed iteration: the step ‖x_l − x_{l−1}‖∞, the residual ‖G − x‖∞ at the
  // last evaluated point (NaN when unknown) and ‖x_l‖∞. Returns the final status or nullopt.
  // step_may_converge = false: the step was cut short by the engine (a trust region's radius),
  // so its smallness says nothing about the distance to a root; the step criterion is not
  // applied to it (the residual criterion still is).
  std::optional<Status> update(double step, double residual, double iterate_norm,
                               bool step_may_converge = true) {
    ++iterations_;
    last_step_ = step;
    reason_ = nullptr;  // a reason only for the status of the last update
    // Did ‖F‖ fall by a meaningful fraction below every earlier residual? (NaN: unknown.)
    const double best_before = lowest_residual_;
    const bool residual_known = std::isfinite(residual);
    const bool residual_fell = residual_known && residual < (1.0 - kMeaningfulFall) * best_before;
    if (residual_known && residual < lowest_residual_) lowest_residual_ = residual;
    if (prev_step_ > 0.0) {
      ratios_[ratio_count_ % kRatios] = step / prev_step_;
      ++ratio_count_;
    }
    if (iterate_norm > limit_) {
      return stop(Status::kDiverged, "|x|inf exceeded divergence_limit x max(1, |x0|inf)");
    }
    constexpr double kNoStep = std::numeric_limits<double>::infinity();
    const double relative = step / (iterate_norm + 1.0);
    if (converged(step_may_converge ? (c_.relative_step ? relative : step) : kNoStep,
                  step_may_converge ? step : kNoStep, residual)) {
      return Status::kConverged;
    }

    zero_steps_ = (step == 0.0) ? zero_steps_ + 1 : 0;
    if (c_.stop_on_repeated_iterates && zero_steps_ >= 2) {
      return stop(Status::kRepeatedIterates, "x_l = x_(l-1) = x_(l-2)");
    }
    // The rounding floor: the step is at the level of rounding in x and ‖F‖ no longer falls,
    // kFloorPatience times in a row. Newton's own step there is J⁻¹ times F's rounding noise,
    // about ε‖x‖, so neither an absolute step tolerance below ε‖x‖ nor a residual tolerance below
    // the noise can ever be met; without this test such a run spends its whole budget.
    const bool rounding_step =
        step <= kRoundingSteps * std::numeric_limits<double>::epsilon() * (iterate_norm + 1.0);
    // Only a full step says so: a step the engine cut short (a trust region's radius, a small
    // pseudo-time step, a damped or projected step) is small for its own reasons.
    floor_count_ = residual_known && step_may_converge && rounding_step && !residual_fell
                       ? floor_count_ + 1
                       : 0;
    if (floor_count_ >= kFloorPatience) {
      return stop(Status::kRoundingFloor,
                  "the step is at the level of rounding in x and |F| no longer falls");
    }
    if (progress_ == Progress::kBestResidual) {
      if (residual < best_before) {  // a new record (NaN: none)
        since_best_ = 0;
        far_above_ = 0;
      } else {
        ++since_best_;
        far_above_ = residual > c_.divergence_growth * best_before ? far_above_ + 1 : 0;
      }
      if (residual_window_ > 0) {
        if (far_above_ >= residual_window_) {
          return stop(Status::kDiverged,
                      "every residual of the last max(residual_window, "
                      "residual_window_per_unknown x n) iterations exceeded divergence_growth x "
                      "the best before them");
        }
        if (since_best_ >= residual_window_) {
          return stop(Status::kStagnated,
                      "no residual of the last max(residual_window, residual_window_per_unknown "
                      "x n) iterations fell below the best before them");
        }
      }
    } else if (iterations_ > 1 && step >= prev_step_) {
      if (non_shrinking_ == 0) {
        run_start_step_ = prev_step_;
        run_start_residual_ = best_before;
      }
      ++non_shrinking_;
      if (c_.stagnation_patience > 0 && non_shrinking_ >= c_.stagnation_patience) {
        // Judged on the residual too (except by the paper's rule, patience 1, which is the step
        // alone): steps that grow while ‖F‖ falls are the way in to a root, not away from it —
        // Newton on X² = A (Hammarling's matrix square root) takes steps 0.5 … 15 with ‖F‖
        // falling at each, then converges.
        const bool residual_fell_over_run =
            c_.stagnation_patience > 1 && residual_known &&
            lowest_residual_ < (1.0 - kMeaningfulFall) * run_start_residual_;
        if (residual_fell_over_run) {
          non_shrinking_ = 0;
        } else {
          const bool grew =
              run_start_step_ > 0.0 ? step > c_.divergence_growth * run_start_step_ : step > 0.0;
          return grew ? stop(Status::kDiverged,
                             "the step grew more than divergence_growth x over "
                             "stagnation_patience iterations while |F| did not fall 0.1 %")
                      : stop(Status::kStagnated,
                             "the steps did not shrink over stagnation_patience iterations "
                             "while |F| did not fall 0.1 %");
        }
      }
    } else {
      non_shrinking_ = 0;
    }
    if (iterations_ >= c_.max_iterations) return stop(Status::kMaxIterations, nullptr);
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
  // the a priori iteration count into the summary; and, when the run ended with the status this
  // monitor returned and the engine left no message, the rule that ended it.
  void fill(Summary& s, double residual) const {
    if (s.message.empty() && reason_ && stopped_ == s.status) s.message = reason_;
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
  static constexpr double kMeaningfulFall = kMeaningfulResidualFall;
  // A step is at the level of rounding in x when ‖Δx‖∞ ≤ kRoundingSteps · ε · (‖x‖∞ + 1):
  // 2.2e-12 relative. An engine converging linearly with contraction L > 1 − kMeaningfulFall has
  // a residual that no longer "falls" by this rule, so it is named at the floor there, within
  // about 2.2e-12/(1 − L) relative of its limit (2.2e-8 at L = 0.9999).
  static constexpr double kRoundingSteps = 1e4;
  static constexpr int kFloorPatience = 3;

  // step_test: the step the step criterion judges (relative or not); step: ‖Δx‖∞ for the error
  // bound. Both inf for a step cut short.
  bool converged(double step_test, double step, double residual) const {
    int enabled = 0, met = 0;
    auto test = [&](bool on, bool ok) {
      enabled += on;
      met += on && ok;
    };
    test(c_.step_tolerance.has_value(), c_.step_tolerance && step_test <= *c_.step_tolerance);
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

  // The status update() returns, with the rule's reason for Summary::message (static text).
  Status stop(Status status, const char* reason) {
    stopped_ = status;
    reason_ = reason;
    return status;
  }

  StopCriteria c_;
  Status stopped_ = Status::kConverged;
  const char* reason_ = nullptr;
  double limit_;
  bool estimate_lipschitz_;
  Progress progress_;
  long residual_window_;  // in force: max(residual_window, ⌈residual_window_per_unknown · n⌉)
  long since_best_ = 0, far_above_ = 0;  // iterations since the best residual; run above growth×
  int iterations_ = 0;
  double prev_step_ = 0.0;
  double last_step_ = 0.0;
  double run_start_step_ = 0.0;
  double run_start_residual_ = std::numeric_limits<double>::infinity();
  double lowest_residual_ = std::numeric_limits<double>::infinity();  // over every iteration
  int floor_count_ = 0;
  int non_shrinking_ = 0;
  int zero_steps_ = 0;
  double ratios_[kRatios] = {0.0, 0.0, 0.0};
  int ratio_count_ = 0;
};

// StopCriteria::progress_window: counts the evaluations of F at iterates and trial points since
// ‖F‖₂ last fell below (1 − kMeaningfulResidualFall) × its value at the fall before (the
// anchor), for the engines that see every evaluation (SquareSystem, Levenberg–Marquardt). A
// crawl of 1e-4 relative per evaluation makes progress every eleven evaluations; jitter at a
// floor none. No allocation until message().
class ProgressWindow {
 public:
  void start(int window) {
    window_ = window;
    count_ = last_fall_ = 0;
    anchor_ = std::numeric_limits<double>::infinity();
  }
  // After an evaluation: ‖F‖₂ there (NaN or inf when F is not finite: no progress).
  void saw(double norm) {
    ++count_;
    if (norm < (1.0 - kMeaningfulResidualFall) * anchor_) {
      anchor_ = norm;
      last_fall_ = count_;
    }
  }
  // The window has passed without progress (never when it is off).
  bool expired() const { return window_ > 0 && count_ - last_fall_ >= window_; }
  // Why the run stagnated, for Summary::message.
  std::string message() const {
    char text[160];
    std::snprintf(text, sizeof text,
                  "|F|_2 has not fallen below 0.999 x %.6g in the last %d evaluations "
                  "(StopCriteria::progress_window)",
                  anchor_, window_);
    return text;
  }

 private:
  int window_ = 0, count_ = 0, last_fall_ = 0;
  double anchor_ = std::numeric_limits<double>::infinity();
};

}  // namespace nlobs
