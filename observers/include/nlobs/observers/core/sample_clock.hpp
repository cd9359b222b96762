#pragma once
// How a discrete-time observer (EKF, UKF, MHE, Luenberger, sliding mode, window estimators)
// moves its model from one sample to the next by the samples' times. A discrete model steps by
// T, its sample time (sample_time_of; a model that declares none takes its first interval as T).
// Sample k at t, after the last one placed at t′:
//  * on the grid, t − t′ = m·T within the rounding of recorded times (tolerance()): m moves
//    of one step each (m − 1 of them over samples that did not come: a gap, as a missing y), at
//    the grid times t′ + j·T, so that the rounding of recorded times never enters the estimate;
//  * off the grid: one move over the actual interval t − t′ when the model has a flow (the
//    discretisations of a continuous model integrate over any interval) and the observer takes
//    irregular samples; otherwise the failure "non_uniform", naming the sample and why (a
//    fixed-step model; an observer whose gain is designed for the step T);
//  * at t′ (within rounding): no move — a second measurement of the same instant, for observers
//    that take one (a Kalman filter updates twice); the others refuse it ("non_uniform");
//  * before t′: "non_uniform"; a t that is not finite: "non_finite".
// A refused sample leaves the clock as it was. A move is a ModelStep: advance() applies it,
// generic in the scalar so that a move's Jacobian comes by AD, and its weight (its length / T)
// scales a process-noise covariance given per step T, Q ← weight · Q (the first-order
// discretisation of a constant noise intensity).
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <utility>

#include "nlobs/models/model.hpp"
#include "nlobs/observers/core/model_step.hpp"
#include "nlobs/observers/core/observer.hpp"

namespace nlobs {

// Half-width, in grid steps, of "on the grid" at time t for a grid step T: recorded times carry
// their decimal rounding (`rounding` steps; the sampled-data observers' 1e-6 by default), plus a
// few ulps of t relative to T.
inline double grid_tolerance(double t, double step, double rounding = 1e-6) {
  return rounding + 4.0 * std::numeric_limits<double>::epsilon() * std::abs(t) / step;
}

class SampleClock {
 public:
  // The longest interval between two samples, in sample times: a gap is that many steps of the
  // model, so it is bounded.
  static constexpr double kLongestInterval = 1e6;

  // Half-width, in steps T, of "on the grid" (and "the same instant") at time t: recorded times
  // carry their decimal rounding — six decimals at T = 1/30 are 1e-5 T off — plus a few ulps
  // of t relative to T. Moves on the grid use the grid time, so the rounding never enters.
  static double tolerance(double t, double step) { return grid_tolerance(t, step, 1e-4); }

  // `sample_time`: T > 0, or 0 for a model that declares none (its first interval is taken; so
  // is a T that is not finite and > 0);
  // `flow`: the model integrates over any interval; `needs_grid`: empty when the observer
  // integrates over an irregular interval, else why it cannot (the refusal says it);
  // `same_time`: a sample at the last one's time is taken (no move) rather than refused.
  SampleClock(double sample_time, bool flow, std::string needs_grid, bool same_time)
      : declared_(std::isfinite(sample_time) && sample_time > 0.0 ? sample_time : 0.0),
        flow_(flow),
        needs_grid_(std::move(needs_grid)),
        same_time_(same_time) {
    reset();
  }
  template <DiscreteModel Model>
  static SampleClock of(const Model& model, std::string needs_grid, bool same_time) {
    return SampleClock(sample_time_of(model), has_interval_flow(model), std::move(needs_grid),
                       same_time);
  }

  void reset() {
    step_ = declared_;
    started_ = false;
    origin_ = 0.0;
    offset_ = index_ = 0;
    pending_ = Pending{};
  }

  // Places sample k at t: true with moves() and move(j) set for the way from the last sample
  // (commit() then moves the clock to it); false with the step's failure and message set
  // (naming `who`, k, t and why) and the clock unchanged.
  bool place(const std::string& who, long k, double t, ObserverStep& step) {
    pending_ = Pending{};
    if (!std::isfinite(t)) return refuse(step, "non_finite", who, k, t, "its time is not finite");
    if (!started_) {
      pending_.first = true;
      pending_.time = t;
      pending_.index = k;
      pending_.step = step_;
      return true;
    }
    const double last = time();
    const double interval = t - last;
    const double scale = step_ > 0.0 ? step_ : std::abs(interval);
    const double rounding =
        scale > 0.0 ? tolerance(std::max(std::abs(t), std::abs(last)), scale) : 0.0;
    if (!(rounding < 0.25)) {
      return refuse(step, "non_uniform", who, k, t,
                    "the time is too large for the sample time T to be resolved (its rounding "
                    "exceeds a quarter step)");
    }
    if (interval == 0.0 || (step_ > 0.0 && std::abs(interval) <= rounding * step_)) {
      if (!same_time_) {
        return refuse(step, "non_uniform", who, k, t,
                      "it comes at the last sample's time; this observer takes one sample per "
                      "instant");
      }
      pending_.step = step_;
      return true;
    }
    if (!(interval > 0.0)) {
      std::ostringstream os;
      os << "its time does not come after the last sample's (t = " << last << ")";
      return refuse(step, "non_uniform", who, k, t, os.str());
    }
    // A model that declares no T takes its first interval.
    const double grid = step_ > 0.0 ? step_ : interval;
    if (interval / grid > kLongestInterval) {  // a bounded number of steps, always
      std::ostringstream os;
      os << "its interval " << interval << " since the last sample exceeds " << kLongestInterval
         << " sample times (T = " << grid << "); reset() the observer to start afresh";
      return refuse(step, "non_uniform", who, k, t, os.str());
    }
    const double m = std::round(interval / grid);
    if (m >= 1.0 && std::abs(interval / grid - m) <= rounding) {
      pending_.moves = static_cast<long>(m);
      pending_.step = grid;
      return true;
    }
    if (!needs_grid_.empty() || !flow_) {
      std::ostringstream os;
      os << "its interval " << interval
         << " since the last sample is not a multiple of T = " << grid << " (nearest grid time "
         << last + std::max(m, 1.0) * grid << "); "
         << (!needs_grid_.empty() ? needs_grid_
                                  : "the model has a fixed step (no flow over an interval)")
         << ": it needs samples on the grid";
      return refuse(step, "non_uniform", who, k, t, os.str());
    }
    pending_.moves = 1;
    pending_.irregular = true;
    pending_.time = t;
    pending_.step = grid;
    return true;
  }

  // The moves from the last sample to the one placed (0: the first sample, or the same instant).
  long moves() const { return pending_.moves; }
  // Move j < moves(). A fixed-step model takes f at the model index: the first sample's k plus
  // the grid steps since.
  ModelStep move(long j) const {
    ModelStep s;
    s.index = index_ + j;
    s.flow = flow_;
    const double last = time();
    if (pending_.irregular) {
      s.time = last;
      s.length = pending_.time - last;
      s.weight = s.length / pending_.step;
    } else {
      s.time = origin_ + static_cast<double>(offset_ + j) * pending_.step;
      s.length = pending_.step;
    }
    return s;
  }
  // Moves the clock to the sample placed (the observer took it).
  void commit() {
    step_ = pending_.step;
    if (pending_.first || pending_.irregular) {
      origin_ = pending_.time;
      offset_ = 0;
      index_ = pending_.first ? pending_.index : index_ + 1;
    } else {
      offset_ += pending_.moves;
      index_ += pending_.moves;
    }
    started_ = true;
    pending_ = Pending{};
  }
  // The time of the last sample committed (on the grid: its grid time, origin + m·T).
  double time() const { return origin_ + static_cast<double>(offset_) * step_; }
  // The model index of the last sample committed (the first sample's k plus the grid steps).
  long index() const { return index_; }
  bool started() const { return started_; }
  double sample_time() const { return step_; }  // T (0 until known)

 private:
  bool refuse(ObserverStep& step, const char* failure, const std::string& who, long k, double t,
              const std::string& why) const {
    std::ostringstream os;
    os << who << ": sample k = " << k << " at t = " << t << " is refused: " << why;
    step.failure = failure;
    step.failure_message = os.str();
    return false;
  }

  struct Pending {  // the placement of the last sample, until commit()
    bool first = false, irregular = false;
    long moves = 0;
    double time = 0.0;  // the first sample's time, or an irregular one's
    long index = 0;     // the first sample's k
    double step = 0.0;  // T after it
  };

  double declared_, step_ = 0.0;
  bool flow_;
  std::string needs_grid_;
  bool same_time_;
  bool started_ = false;
  // The last sample committed stands at origin_ + offset_·T (origin_: the first sample's time,
  // or the last one off the grid), at the model index index_.
  double origin_ = 0.0;
  long offset_ = 0, index_ = 0;
  Pending pending_;
};

}  // namespace nlobs
