#pragma once
// The sampled-data skeleton shared by the observers that integrate continuous dynamics between
// samples (MVT, high-gain, PI bank), written once: each sample is placed by its time on the
// grid t_0 + m·T (UniformGrid below: off the grid is refused, skipped points are a gap); its
// size is checked and the
// samples must come in order (both errors thrown, naming the observer); a u_k that is not
// finite is a failure ("non_finite", the state kept: u is known by assumption); a y_k that is
// not finite is a missing measurement (the state held, the next good sample bridges the gap at
// the usual step length); the first good sample starts the observer; each later one is
// integrated over [t_{k−1}, t_k] with y between samples interpolated through the last good
// samples (cubic, or linear for the PI bank) and u held at u_{k−1} (the plant's sampled input).
// A step the observer cannot take (its dynamics not finite) is rejected: the sample is
// forgotten as if it were missing — the interpolation included — and the next good one
// integrates from the last good state and time. The integration itself is
// interval_integrator.hpp's.
//
//   switch (clock_.receive(options_.name, k, t, y, u, step_)) {
//     case SampledData<P, M>::kHold: return publish();
//     case SampledData<P, M>::kStart: ...start...; clock_.accept(); break;
//     case SampledData<P, M>::kIntegrate:
//       if (!integrate(clock_.last_time(), clock_.time())) {
//         clock_.reject(step_, failure_);
//         return publish();
//       }
//       clock_.accept();
//   }
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <utility>

#include "nlobs/common/invalid_input.hpp"
#include "nlobs/observers/core/observer.hpp"
#include "nlobs/observers/core/sample_clock.hpp"
#include "nlobs/observers/core/sample_interpolator.hpp"

namespace nlobs {

// A sample's place on a uniform grid: its index m and time t_0 + m·T.
struct GridPoint {
  long index = 0;
  double time = 0.0;
};

// The uniform grid t_0 + m·T of an observer that assumes uniform sampling, samples placed by
// their time: t_0 is the first sample's time, a later sample must lie on a grid point after the
// last one placed, and the grid points it skips are samples that did not come (a dropped row
// of recorded data is a gap, as a missing y is). Observers integrate (or divide) with the grid
// time, so that the rounding of recorded times does not enter the estimate.
class UniformGrid {
 public:
  explicit UniformGrid(double sample_time) : sample_time_(sample_time) {}
  void reset() {
    origin_.reset();
    last_ = -1;
  }
  double sample_time() const { return sample_time_; }

  // Sample k taken at t; nullopt when t is not finite (failure "non_finite"), off the grid, not
  // after the last sample placed, or too large for T to be resolved (failure "non_uniform"),
  // with what and where in the step's message.
  std::optional<GridPoint> place(const std::string& who, long k, double t, ObserverStep& step) {
    if (!std::isfinite(t)) {
      return refuse(step, "non_finite", who, k, t, "the sample time is not finite");
    }
    // The position's rounding grows with the larger of t and t_0 (data from a large negative
    // epoch crossing 0).
    const double tolerance =
        grid_tolerance(origin_ ? std::max(std::abs(t), std::abs(*origin_)) : t, sample_time_);
    if (!(tolerance < 0.25)) {  // |t| / T < 2.8e14: the indices below fit a long
      return refuse(step, "non_uniform", who, k, t,
                    "the time is too large for a grid step of T (its rounding exceeds a "
                    "quarter step)");
    }
    if (!origin_) origin_ = t;
    const double position = (t - *origin_) / sample_time_;
    const double m = std::round(position);
    if (!(std::abs(position - m) <= tolerance)) {
      std::ostringstream os;
      os << "the time is off the uniform grid t_0 + m·T (t_0 = " << *origin_
         << "; nearest grid time " << *origin_ + m * sample_time_
         << "); this observer needs uniform samples";
      return refuse(step, "non_uniform", who, k, t, os.str());
    }
    if (!(m > static_cast<double>(last_))) {
      std::ostringstream os;
      os << "the time does not come after the last sample's (t = "
         << *origin_ + static_cast<double>(last_) * sample_time_ << ")";
      return refuse(step, "non_uniform", who, k, t, os.str());
    }
    last_ = static_cast<long>(m);
    return GridPoint{last_, *origin_ + m * sample_time_};
  }

 private:
  std::nullopt_t refuse(ObserverStep& step, const char* failure, const std::string& who, long k,
                        double t, const std::string& what) const {
    std::ostringstream os;
    os << who << ": sample k = " << k << " at t = " << t << " (T = " << sample_time_
       << "): " << what;
    step.failure = failure;
    step.failure_message = os.str();
    return std::nullopt;
  }

  double sample_time_;
  std::optional<double> origin_;
  long last_ = -1;  // the index of the last sample placed
};

template <int P, int M>
class SampledData {
 public:
  using Output = Eigen::Matrix<double, P, 1>;
  using Input = Eigen::Matrix<double, M, 1>;
  enum Action { kHold, kStart, kIntegrate };

  // T > 0 (the observer's validated sample_time); y through the last `points` samples (4:
  // cubic, 2: linear).
  SampledData(Eigen::Index outputs, Eigen::Index inputs, double sample_time, int points = 4)
      : grid_(sample_time),
        samples_(outputs, points),
        before_(outputs, points),
        held_(Input::Zero(inputs)) {}

  void reset() {
    grid_.reset();
    placed_ = false;
    samples_.clear();
    started_ = false;
    t_ = last_t_ = 0.0;
    held_.setZero();
  }

  // Sample k at time t: throws InvalidInput (`who`: the observer's name) for y or u of the wrong
  // size and for a k that does not come after the last one placed on the grid (taken, held or
  // rejected: only a sample refused for its time may come again). Clears the step's failure
  // and sets measurement_missing; kHold for a t off the grid (UniformGrid::place's failures), a
  // missing y_k, and a u_k that is not finite (failure "non_finite", said in the step); otherwise
  // the sample is recorded and the answer is kStart (the observer has not started) or kIntegrate
  // ([last_time(), time()], grid times).
  Action receive(const std::string& who, long k, double t, const Eigen::VectorXd& y,
                 const Eigen::VectorXd& u, ObserverStep& step) {
    if (y.size() != samples_.outputs() || u.size() != held_.size()) {
      std::ostringstream os;
      os << who << ": sample k = " << k << " has y of size " << y.size() << " and u of size "
         << u.size() << "; the observer takes sizes " << samples_.outputs() << " and "
         << held_.size();
      throw InvalidInput(os.str());
    }
    if (placed_ && !(k > last_k_)) {
      throw InvalidInput(who + ": sample k = " + std::to_string(k) +
                         " does not come after the last one: samples must arrive in order");
    }
    step.failure.clear();
    step.failure_message.clear();
    step.measurement_missing = false;
    const std::optional<GridPoint> point = grid_.place(who, k, t, step);
    if (!point) return kHold;
    placed_ = true;  // a held or rejected sample k has come too: k again is out of order
    last_k_ = k;
    step.measurement_missing = !y.allFinite();
    t_ = point->time;
    if (!u.allFinite()) {
      step.failure = "non_finite";
      std::ostringstream os;
      os << who << ": u_k is not finite at t = " << t_ << " (sample k = " << k << ")";
      step.failure_message = os.str();
      return kHold;
    }
    if (step.measurement_missing) return kHold;
    before_ = samples_;
    samples_.push(t_, y);
    current_u_ = u;
    return started_ ? kIntegrate : kStart;
  }

  double time() const { return t_; }            // t_k of the sample received
  double last_time() const { return last_t_; }  // the last sample taken
  bool started() const { return started_; }
  const Input& held_input() const { return held_; }  // u_{k−1}, over [t_{k−1}, t_k]
  Output output_at(double t) const { return samples_.at(t); }
  void output_at(double t, Output& y) const { samples_.at(t, y); }

  // The observer took the sample (started on it, or integrated up to it).
  void accept() {
    started_ = true;
    last_t_ = t_;
    held_ = current_u_;
  }

  // It could not: the sample is forgotten as if missing (failure "non_finite" with `message`);
  // the next good one goes on from last_time() and the last good state.
  void reject(ObserverStep& step, std::string message) {
    samples_ = before_;
    step.failure = "non_finite";
    step.failure_message = std::move(message);
  }

 private:
  UniformGrid grid_;
  SampleInterpolator<P> samples_, before_;
  Input held_, current_u_ = Input::Zero(held_.size());
  bool started_ = false;
  double t_ = 0.0, last_t_ = 0.0;
  bool placed_ = false;  // a sample was placed on the grid since the last reset()
  long last_k_ = 0;      // the k of the last one
};

}  // namespace nlobs
