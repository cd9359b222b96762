#pragma once
// What the simulation harness runs side by side: anything that turns a stream of samples
// (y_k, u_k) into estimates x̂_k. Sizes are dynamic at this interface; observers keep their
// own (possibly fixed-size) state inside.
#include <Eigen/Core>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "nlobs/solvers/summary.hpp"

namespace nlobs {

struct ObserverStep {
  Eigen::VectorXd estimate;          // x̂_k; finite (accept_finite() keeps it so)
  bool ready = true;                 // false while a window fills (the estimate coasts on f)
  bool measurement_missing = false;  // y_k had a non-finite entry: skipped, estimate coasts
  std::optional<Summary> summary;    // the engine's summary when this step solved a window
  Eigen::VectorXd extras;  // further named signals (extra_names()), e.g. η̂₁ of a PI bank
  // Empty, or why this step kept the last good state ("non_finite", "non_finite_estimate", …).
  std::string failure;
  std::string failure_message;  // what and where, for the report
};

class Observer {
 public:
  virtual ~Observer() = default;
  virtual std::string name() const = 0;              // e.g. "window:steffensen", "luenberger"
  virtual std::string engine() const { return {}; }  // engine spec, for window estimators
  // Window length N for window estimators (0 otherwise): the harness's "after the window".
  virtual Eigen::Index window() const { return 0; }
  // Names of the signals in ObserverStep::extras (written beside x̂ by `nlobs run`).
  virtual std::vector<std::string> extra_names() const { return {}; }
  // What a user should know about this observer's set-up (e.g. derivatives by finite
  // differences because the model does not support AD); printed and kept in summary.json.
  virtual std::vector<std::string> warnings() const { return {}; }
  // Observers that estimate in other coordinates (the high-gain observer's z = q_N(x), published
  // as the extras zhat1…): the image of a true state, so that a harness can measure the error
  // there. Empty for observers that estimate x directly.
  virtual Eigen::VectorXd coordinates_of(const Eigen::VectorXd& /*x*/) const { return {}; }
  // The same at time t, for coordinates that move with t (the modulating-function observer's
  // canonical state of a time-varying system).
  virtual Eigen::VectorXd coordinates_at(const Eigen::VectorXd& x, double /*t*/) const {
    return coordinates_of(x);
  }
  virtual void reset() = 0;  // back to the initial guess, empty window
  // Sample k (consecutive from 0). A non-finite y means a missing measurement.
  virtual const ObserverStep& step(long k, const Eigen::VectorXd& y, const Eigen::VectorXd& u) = 0;
  // Sample k taken at time t (recorded data carry their times): observers that need uniform
  // sampling check it here; the others ignore t.
  virtual const ObserverStep& step_at(long k, double /*t*/, const Eigen::VectorXd& y,
                                      const Eigen::VectorXd& u) {
    return step(k, y, u);
  }
};

// Marks a step whose estimate (or what it is computed from) was not finite and was not taken.
inline void mark_non_finite_estimate(ObserverStep& step, std::string message) {
  step.failure = "non_finite_estimate";
  step.failure_message = std::move(message);
}

// The one rule for an observer's own state: `next` replaces `state` only when it is finite;
// otherwise the state keeps its last finite value and the step says so (failure
// "non_finite_estimate", with who, k and what overflowed). Returns whether `next` was taken.
template <typename State>
bool accept_finite(const State& next, State& state, ObserverStep& step, const std::string& who,
                   long k, const char* what = "the next estimate") {
  if (next.allFinite()) {
    state = next;
    return true;
  }
  std::ostringstream os;
  os << who << ": " << what << " at sample k = " << k
     << " is not finite; kept the last finite estimate";
  mark_non_finite_estimate(step, os.str());
  return false;
}

}  // namespace nlobs
