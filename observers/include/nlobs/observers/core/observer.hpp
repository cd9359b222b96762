#pragma once
// What the simulation harness runs side by side: anything that turns a stream of samples
// (t_k, y_k, u_k) into estimates x̂_k. Sizes are dynamic at this interface; observers keep their
// own (possibly fixed-size) state inside.
//
// The interface is three calls, as control-toolbox's estimators and mherb/kalman's filters have
// it: reset(), step(k, t, y, u) and, for observers that estimate in other coordinates,
// coordinates_at(x, t). What describes the observer — name, engine, window length, warnings,
// the signals published beside x̂ — is one ObserverInfo, set by the constructor (a window
// estimator adds to its warnings what a run finds; reset() clears those).
#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "nlobs/common/invalid_input.hpp"
#include "nlobs/solvers/summary.hpp"

namespace nlobs {

// What a published signal is, so that a report finds it by its role and not by its spelling.
// An observer of a user's own that publishes ẑ as kEmbeddedEstimate gets [HG-EMB23]'s figures;
// one that publishes a per-sample residual as kSolveResidual gets its largest value reported.
enum class SignalKind {
  kDiagnostic,          // written beside x̂ (trajectory.csv, signals plots); no report reads it
  kSolveResidual,       // residual of the per-sample solve, e.g. ‖X(β)‖ of [MGFF23]: its max
  kEmbeddedEstimate,    // ẑ_i, the estimate in embedded coordinates z = q(x) ([HG-EMB23]), in
                        // order; coordinates_at(x, t) gives q(x)
  kProjectionResidual,  // ‖q(x̂) − ẑ‖ of the projection back to x ([HG-EMB23])
  kJumpCount,           // the projection's jumps (restarts) so far
  kCanonicalEstimate,   // η̂_j, the estimate in canonical coordinates η = T(t)x ([MF-LTV]), in
                        // order; coordinates_at(x, t) gives T(t)x
  kCanonicalBound,      // a guaranteed bound on the canonical error (Theorem 1 of [MF-LTV])
  // Added by a harness that knows the true x (cli add_coordinate_errors); run_observers refuses
  // an observer that publishes one:
  kEmbeddedError,   // ‖q(x) − ẑ‖₂
  kCanonicalError,  // ‖T(t)x − η̂‖₂
  kCanonicalNorm,   // ‖T(t)x‖₂, the scale of the relative canonical error
};

struct SignalInfo {
  std::string name;  // a column name: "beta1", "zhat2", "eta1_hat" (no commas needed)
  SignalKind kind = SignalKind::kDiagnostic;
};

// The rows of `signals` of one kind, in order (empty when none).
inline std::vector<Eigen::Index> signal_rows(const std::vector<SignalInfo>& signals,
                                             SignalKind kind) {
  std::vector<Eigen::Index> rows;
  for (std::size_t i = 0; i < signals.size(); ++i) {
    if (signals[i].kind == kind) rows.push_back(static_cast<Eigen::Index>(i));
  }
  return rows;
}

// The first row of one kind.
inline std::optional<Eigen::Index> signal_row(const std::vector<SignalInfo>& signals,
                                              SignalKind kind) {
  for (std::size_t i = 0; i < signals.size(); ++i) {
    if (signals[i].kind == kind) return static_cast<Eigen::Index>(i);
  }
  return std::nullopt;
}

struct ObserverInfo {
  std::string name;    // e.g. "window:steffensen", "luenberger": reports, columns, plots
  std::string engine;  // the label of the engine it solves with (Engine::label()); empty if none
  // Samples before the first full estimate (a window estimator's N, a modulating horizon's
  // L + 1; 0 otherwise): the harness's "after the window" starts at the longest one's N − 1.
  Eigen::Index window = 0;
  // What a user should know about the set-up (e.g. derivatives by finite differences because
  // the model does not support AD), and what a window estimator's run found (a Ψ that does not
  // contract; cleared by reset()); printed and kept in summary.json.
  std::vector<std::string> warnings;
  std::vector<SignalInfo> signals;  // the entries of ObserverStep::signals, in order
  // The name of the model the observer runs on, for messages ("observer 'ekf' on model 'x'
  // threw: …"); set by whoever knows it (the registry's build_observer), empty otherwise.
  std::string model;
};

struct ObserverStep {
  // x̂_k; finite once the observer has started (a PI bank publishes NaN before its first good
  // sample; accept_finite() keeps it finite after).
  Eigen::VectorXd estimate;
  bool ready = true;  // false while a window fills (the estimate coasts on f)
  // y_k is missing: every entry non-finite for the observers that take the outputs a sample has
  // (EKF, UKF, MHE, Luenberger, sliding mode), any entry for those that need them all (window and
  // sampled-data observers); the estimate coasts
  bool measurement_missing = false;
  std::optional<Summary> summary;  // the engine's summary when this step solved a window
  // The observer took the answer although summary->usable() is false: a moving-horizon
  // estimator's solve cut short (or its one real-time iteration) still lowered its cost from the
  // warm start. Reports then say "used", not "not used".
  bool used_unusable_answer = false;
  Eigen::VectorXd signals;  // the values of ObserverInfo::signals at this step
  // Empty, or why this step kept the last good state ("non_finite", "non_uniform", …).
  std::string failure;
  std::string failure_message;  // what and where, for the report
};

class Observer {
 public:
  virtual ~Observer() = default;

  const ObserverInfo& info() const { return info_; }
  const std::string& name() const { return info_.name; }
  // ObserverInfo::model: what a report names when this observer's step throws.
  void set_model_name(std::string model) { info_.model = std::move(model); }

  virtual void reset() = 0;  // back to the initial estimate, empty window
  // Sample k (0, 1, 2, … in order) taken at time t. A non-finite entry of y is a missing
  // measurement of that output. Every observer places the sample by t: the sampled-data ones
  // (MVT, high-gain, PI bank, backward differences, modulating functions) on their uniform grid
  // t_0 + m·T (t_0 the first sample's time; skipped grid points are a gap) and refuse one off it
  // (failure "non_uniform") or with a non-finite t ("non_finite"); the discrete-time ones move
  // their model from the last sample's time to t (SampleClock, sample_clock.hpp: a gap on the
  // model's grid is that many steps, an interval off it is integrated by a model with a flow
  // for the Kalman-type observers and refused by the others).
  virtual const ObserverStep& step(long k, double t, const Eigen::VectorXd& y,
                                   const Eigen::VectorXd& u) = 0;
  // For observers that estimate in other coordinates (signals of kind kEmbeddedEstimate or
  // kCanonicalEstimate): the image of a true state x at time t there, so that a harness can
  // measure the error in those coordinates. Empty for observers that estimate x directly.
  virtual Eigen::VectorXd coordinates_at(const Eigen::VectorXd& /*x*/, double /*t*/) const {
    return {};
  }

 protected:
  Observer() = default;
  explicit Observer(ObserverInfo info) : info_(std::move(info)) {}
  Observer(const Observer&) = default;
  Observer& operator=(const Observer&) = default;
  Observer(Observer&&) = default;
  Observer& operator=(Observer&&) = default;

  ObserverInfo info_;  // filled by the constructor (see ObserverInfo::warnings)
};

// Throws InvalidInput naming `who` and k when sample k's y or u does not have the model's sizes.
inline void require_sample_sizes(const std::string& who, long k, const Eigen::VectorXd& y,
                                 const Eigen::VectorXd& u, Eigen::Index outputs,
                                 Eigen::Index inputs) {
  if (y.size() == outputs && u.size() == inputs) return;
  std::ostringstream os;
  os << who << ": the sample k = " << k << " has " << y.size() << " outputs and " << u.size()
     << " inputs; the model has " << outputs << " and " << inputs;
  throw InvalidInput(os.str());
}

// The entries of y that were measured (finite), in order: a sample may carry only some outputs.
inline std::vector<Eigen::Index> measured_outputs(const Eigen::VectorXd& y) {
  std::vector<Eigen::Index> rows;
  for (Eigen::Index i = 0; i < y.size(); ++i) {
    if (std::isfinite(y[i])) rows.push_back(i);
  }
  return rows;
}

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
