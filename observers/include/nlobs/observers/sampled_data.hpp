#pragma once
// The sampled-data skeleton shared by the observers that integrate continuous dynamics between
// samples (MVT, high-gain, PI bank), written once: sample k is taken at t_k = k·T; its size is
// checked and the samples must come in order (both errors thrown, naming the observer); a u_k
// that is not finite is a failure ("non_finite", the state kept: u is known by assumption); a
// y_k that is not finite is a missing measurement (the state held, the next good sample
// bridges the gap at the usual step length); the first good sample starts the observer; each
// later one is integrated over [t_{k−1}, t_k] with y between samples interpolated through the
// last good samples (cubic, or linear for the PI bank) and u held at u_{k−1} (the plant's
// sampled input). A step the observer cannot take (its dynamics not finite) is rejected: the
// sample is forgotten as if it were missing — the interpolation included — and the next good
// one integrates from the last good state and time. The integration itself is
// interval_integrator.hpp's.
//
//   switch (clock_.receive(options_.name, k, y, u, step_)) {
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
#include <cmath>
#include <sstream>
#include <string>
#include <utility>

#include "nlobs/common/invalid_input.hpp"
#include "nlobs/observers/observer.hpp"
#include "nlobs/observers/sample_interpolator.hpp"

namespace nlobs {

template <int P, int M>
class SampledData {
 public:
  using Output = Eigen::Matrix<double, P, 1>;
  using Input = Eigen::Matrix<double, M, 1>;
  enum Action { kHold, kStart, kIntegrate };

  // T > 0 (the observer's validated sample_time); y through the last `points` samples (4:
  // cubic, 2: linear).
  SampledData(Eigen::Index outputs, Eigen::Index inputs, double sample_time, int points = 4)
      : sample_time_(sample_time),
        samples_(outputs, points),
        before_(outputs, points),
        held_(Input::Zero(inputs)) {}

  void reset() {
    samples_.clear();
    started_ = false;
    t_ = last_t_ = 0.0;
    held_.setZero();
  }

  // Sample k: throws InvalidInput (`who`: the observer's name) for y or u of the wrong size and
  // for a sample that does not come after the last one taken. Clears the step's failure and sets
  // measurement_missing; kHold for a missing y_k, and for a u_k that is not finite (failure
  // "non_finite", said in the step); otherwise the sample is recorded and the answer is kStart
  // (the observer has not started) or kIntegrate ([last_time(), time()]).
  Action receive(const std::string& who, long k, const Eigen::VectorXd& y, const Eigen::VectorXd& u,
                 ObserverStep& step) {
    if (y.size() != samples_.outputs() || u.size() != held_.size()) {
      std::ostringstream os;
      os << who << ": sample k = " << k << " has y of size " << y.size() << " and u of size "
         << u.size() << "; the observer takes sizes " << samples_.outputs() << " and "
         << held_.size();
      throw InvalidInput(os.str());
    }
    t_ = static_cast<double>(k) * sample_time_;
    if (started_ && !(t_ > last_t_)) {
      throw InvalidInput(who + ": sample k = " + std::to_string(k) +
                         " does not come after the last one: samples must arrive in order");
    }
    step.failure.clear();
    step.failure_message.clear();
    step.measurement_missing = !y.allFinite();
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
  double sample_time_;
  SampleInterpolator<P> samples_, before_;
  Input held_, current_u_ = Input::Zero(held_.size());
  bool started_ = false;
  double t_ = 0.0, last_t_ = 0.0;
};

}  // namespace nlobs
