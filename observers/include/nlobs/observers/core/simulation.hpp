#pragma once
// The simulation harness: simulate the true system from x0 (stopping with a clear message if
// it leaves its domain or its state or output becomes non-finite), add seeded Gaussian measurement
// noise, run several observers side by side on identical measurements, and measure them: per-state
// MSE (paper eq. 92) over the whole run and after the window has filled, iterations and evaluations
// per step (mean, max, first window), time per step, failures counted by status.
#include <Eigen/Core>
#include <chrono>
#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "nlobs/common/printable.hpp"
#include "nlobs/models/integration_failure.hpp"
#include "nlobs/models/model.hpp"
#include "nlobs/observers/core/observer.hpp"
#include "nlobs/solvers/status.hpp"

namespace nlobs {

// Samples k = 0..steps−1: x (n × K), y (p × K, noisy as measured), u (m × K), t (K).
struct Measurements {
  Eigen::MatrixXd x;  // true states (empty when the data came from a file)
  Eigen::MatrixXd y;
  Eigen::MatrixXd u;
  Eigen::VectorXd t;  // t_k of every sample (run_observers needs one per sample)
  bool has_truth() const { return x.size() > 0; }
  Eigen::Index steps() const { return y.cols(); }
  // Why the simulation ended early (the domain, a non-finite state or output, a move the
  // discretisation could not integrate), empty otherwise.
  std::string stop_message;
};

struct SimulationOptions {
  long steps = 400;
  double noise_std = 0.0;  // σ of additive Gaussian noise on every output
  // σ_w of additive Gaussian noise on every state at every step, x⁺ = f(x, u, k) + w (the
  // process noise of the MHE literature's examples); drawn after the sample's output noise.
  double process_noise_std = 0.0;
  std::uint64_t seed = 1;
  // T of t_k = k·T. Unset: the model's sample_time() (AnyModel, when it is not 0 = unknown) or
  // step() (Discretized, SampledModel) where it has one, else 1 (samples that are indices).
  std::optional<double> sample_time = std::nullopt;
  std::function<Eigen::VectorXd(long k)> input = {};  // u_k; empty: no inputs
};

// The T of t_k = k·T that simulate() uses: options.sample_time, else the model's, else 1.
template <DiscreteModel Model>
double simulation_sample_time(const Model& model, const SimulationOptions& o) {
  if (o.sample_time) return *o.sample_time;
  if constexpr (requires { model.sample_time(); }) {
    if (model.sample_time() != 0.0) return static_cast<double>(model.sample_time());
  } else if constexpr (requires { model.step(); }) {
    return static_cast<double>(model.step());
  }
  return 1.0;
}

// Throws InvalidInput for steps < 1, σ < 0 or non-finite, a sample time that is not finite and
// > 0, or an x0 of the wrong size; std::runtime_error naming the model (its name() when it has
// one), the sample and its time when the model or the input signal throws — except an
// IntegrationFailure, which stops the simulation as a non-finite state does (stop_message).
template <DiscreteModel Model>
Measurements simulate(const Model& model, const Eigen::VectorXd& x0, const SimulationOptions& o) {
  const Eigen::Index n = model.states(), p = model.outputs(), m = model.inputs();
  if (o.steps < 1) throw InvalidInput("simulate: steps must be >= 1");
  const double sample_time = simulation_sample_time(model, o);
  if (!(sample_time > 0.0) || !std::isfinite(sample_time)) {
    std::ostringstream os;
    os << "simulate: SimulationOptions::sample_time = " << sample_time << " must be finite and > 0";
    throw InvalidInput(os.str());
  }
  if (!(o.noise_std >= 0.0) || !std::isfinite(o.noise_std)) {
    throw InvalidInput("simulate: noise_std must be finite and >= 0");
  }
  if (!(o.process_noise_std >= 0.0) || !std::isfinite(o.process_noise_std)) {
    throw InvalidInput("simulate: process_noise_std must be finite and >= 0");
  }
  if (x0.size() != n || !x0.allFinite()) {
    std::ostringstream os;
    os << "simulate: x0 must be " << n << " finite numbers";
    throw InvalidInput(os.str());
  }
  Measurements data;
  data.x.resize(n, o.steps);
  data.y.resize(p, o.steps);
  data.u.resize(m, o.steps);
  data.t.resize(o.steps);
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  ModelVector<double, Model::kStates> x = x0;
  long k = 0;
  // The true system is the user's model too: whatever it (or the input signal) throws ends the
  // simulation with an error naming the model, the sample and its time. An exception is not a
  // domain exit (the model did not say where its domain ends); InvalidInput is ours, unchanged.
  // IntegrationFailure is the discretisation's (an adaptive or implicit scheme that could not
  // follow the plant): the simulation stops there as at a non-finite state, keeping the samples
  // before it.
  std::string failed_move;
  try {
    for (; k < o.steps; ++k) {
      // Stop where the state leaves its domain or the state or its output is no longer finite:
      // a NaN measurement must never reach the observers.
      std::string violation = failed_move;
      if (violation.empty()) violation = domain_violation_of(model, x);
      Eigen::VectorXd y;
      if (violation.empty() && !x.allFinite()) {
        std::ostringstream os;
        os << "the true state is not finite (x = [" << x.transpose()
           << "]): the model overflowed or left its domain";
        violation = os.str();
      }
      if (violation.empty()) {
        y = model.h(x);
        if (!y.allFinite()) violation = "the output h(x) is not finite";
      }
      if (!violation.empty()) {
        std::ostringstream os;
        os << "stopped at sample " << k << " (t = " << static_cast<double>(k) * sample_time
           << "): " << violation;
        data.stop_message = os.str();
        data.x.conservativeResize(n, k);
        data.y.conservativeResize(p, k);
        data.u.conservativeResize(m, k);
        data.t.conservativeResize(k);
        break;
      }
      const Eigen::VectorXd u = o.input ? o.input(k) : Eigen::VectorXd::Zero(m);
      if (u.size() != m) throw InvalidInput("simulate: the input signal has the wrong size");
      data.x.col(k) = x;
      data.t[k] = static_cast<double>(k) * sample_time;
      data.u.col(k) = u;
      if (o.noise_std > 0.0) {
        for (Eigen::Index i = 0; i < p; ++i) y[i] += o.noise_std * noise(rng);
      }
      data.y.col(k) = y;
      try {
        x = model.f(x, ModelVector<double, Model::kInputs>(u), k);
      } catch (const IntegrationFailure& e) {
        failed_move = "the move from sample " + std::to_string(k) +
                      " could not be integrated: " + printable(e.what());
        continue;
      }
      if (o.process_noise_std > 0.0) {
        for (Eigen::Index i = 0; i < n; ++i) x[i] += o.process_noise_std * noise(rng);
      }
    }
  } catch (const InvalidInput&) {
    throw;
  } catch (...) {
    std::ostringstream os;
    os << "simulate: ";
    if constexpr (requires { model.name(); }) {
      os << "model '" << printable(model.name()) << "'";
    } else {
      os << "the model";
    }
    os << " of the true system threw at sample " << k
       << " (t = " << static_cast<double>(k) * sample_time << "): " << current_exception_text();
    throw std::runtime_error(os.str());
  }
  return data;
}

struct ObserverMetrics {
  std::string name, engine;
  Eigen::VectorXd mse;               // per state, all samples (empty without truth)
  Eigen::VectorXd mse_after_window;  // per state, samples k ≥ settle index
  Eigen::VectorXd max_error_after;   // per state, max_k |x_i − x̂_i| over k ≥ settle index
  double iterations_mean = 0.0;
  int iterations_max = 0;
  int first_window_iterations = 0;  // -1 if no window was solved
  double evaluations_mean = 0.0;
  double ns_per_step = 0.0;
  int solves = 0;
  // Failure name → count: the status of every solve that did not converge, "unusable" for a
  // converged solve whose Summary is not usable(), ObserverStep::failure of every step that set
  // one, "missing_measurement", "non_finite_estimate" for every non-finite estimate that
  // reached the harness (the built-in observers never publish one), and "observer_threw" for
  // every step that threw (run_observers).
  std::map<std::string, int> failures;
  std::optional<Summary> first_window;  // with its trace when the engine records one
  // Why the first failing step failed, with its k and t: the engine's status and message of
  // an unusable solve, an observer's ObserverStep::failure_message, a non-finite estimate, or
  // what a step threw ("observer 'ekf' on model 'm' threw: <what()>").
  std::string first_failure;
};

struct RunResult {
  std::vector<ObserverMetrics> metrics;
  std::vector<Eigen::MatrixXd> estimates;  // per observer: n × K
  std::vector<Eigen::MatrixXd> signals;    // per observer: its published signals × K (or 0 × K)
  std::vector<std::vector<SignalInfo>> signal_info;  // per observer: ObserverInfo::signals
  long settle_index = 0;                             // first sample of "after the window"
};

// Runs every observer over the same measurements (each reset first), sample k at its time
// data.t[k] (required: InvalidInput when data.t does not have one time per sample).
// `settle_index`: the first sample counted in mse_after_window (the longest
// ObserverInfo::window's N − 1 when negative).
// A step that throws anything but InvalidInput (a user's model, engine or observer: `throw 42`
// included) is a failed step, as a non-finite estimate is: counted as "observer_threw", named in
// first_failure (observer, ObserverInfo::model, k, t and the exception's printable text), the
// observer's last estimate and signals kept for that sample (NaN when it threw at its first), and
// the observer is stepped again at the next sample. InvalidInput from a step (a sample of the
// wrong size: the caller's mistake) ends the run, as before.
RunResult run_observers(const Measurements& data, std::vector<std::unique_ptr<Observer>>& observers,
                        long settle_index = -1,
                        const std::function<void(long done, long total)>& progress = {});

// Largest |truth − estimate| per state over samples [from, K) (NaN when the range is empty
// or an estimate there is not finite).
Eigen::VectorXd max_abs_error(const Eigen::MatrixXd& truth, const Eigen::MatrixXd& estimate,
                              long from = 0);

// Mean squared error per state (eq. 92) over samples [from, K).
Eigen::VectorXd mean_squared_error(const Eigen::MatrixXd& truth, const Eigen::MatrixXd& estimate,
                                   long from = 0);

// The first sample index from which ‖x_k − x̂_k‖₂ < threshold for every later sample (a
// non-finite estimate counts as above); -1 when the last sample is not below it.
long first_index_staying_below(const Eigen::MatrixXd& truth, const Eigen::MatrixXd& estimate,
                               double threshold);

}  // namespace nlobs
