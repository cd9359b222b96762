#include "nlobs/observers/core/simulation.hpp"

#include <algorithm>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "nlobs/common/printable.hpp"

namespace nlobs {
namespace {

// Samples counted from `from` on; throws when the two differ in shape.
long samples_from(const char* who, const Eigen::MatrixXd& truth, const Eigen::MatrixXd& estimate,
                  long from) {
  if (truth.rows() != estimate.rows() || truth.cols() != estimate.cols()) {
    throw InvalidInput(std::string(who) + ": truth and estimate differ in shape");
  }
  return static_cast<long>(truth.cols()) - from;
}

}  // namespace

Eigen::VectorXd mean_squared_error(const Eigen::MatrixXd& truth, const Eigen::MatrixXd& estimate,
                                   long from) {
  const long count = samples_from("mean_squared_error", truth, estimate, from);
  if (count <= 0) return Eigen::VectorXd::Constant(truth.rows(), std::nan(""));
  const auto diff = truth.rightCols(count) - estimate.rightCols(count);
  return diff.array().square().rowwise().sum() / static_cast<double>(count);
}

Eigen::VectorXd max_abs_error(const Eigen::MatrixXd& truth, const Eigen::MatrixXd& estimate,
                              long from) {
  const long count = samples_from("max_abs_error", truth, estimate, from);
  if (count <= 0) return Eigen::VectorXd::Constant(truth.rows(), std::nan(""));
  const Eigen::MatrixXd diff = (truth.rightCols(count) - estimate.rightCols(count)).cwiseAbs();
  Eigen::VectorXd out(truth.rows());
  for (Eigen::Index i = 0; i < truth.rows(); ++i) {
    out[i] = diff.row(i).allFinite() ? diff.row(i).maxCoeff() : std::nan("");
  }
  return out;
}

long first_index_staying_below(const Eigen::MatrixXd& truth, const Eigen::MatrixXd& estimate,
                               double threshold) {
  samples_from("first_index_staying_below", truth, estimate, 0);
  long first = -1;
  for (long k = static_cast<long>(truth.cols()) - 1; k >= 0; --k) {
    const double e = (truth.col(k) - estimate.col(k)).norm();
    if (!(e < threshold)) break;  // NaN is not below
    first = k;
  }
  return first;
}

RunResult run_observers(const Measurements& data, std::vector<std::unique_ptr<Observer>>& observers,
                        long settle_index,
                        const std::function<void(long done, long total)>& progress) {
  RunResult result;
  const long steps = static_cast<long>(data.steps());
  if (data.t.size() != data.steps()) {
    throw InvalidInput("run_observers: Measurements::t has " + std::to_string(data.t.size()) +
                       " times for " + std::to_string(data.steps()) +
                       " samples; every sample needs its time");
  }
  if (settle_index < 0) {
    Eigen::Index longest = 1;
    for (const auto& o : observers) longest = std::max(longest, o->info().window);
    settle_index = static_cast<long>(longest) - 1;
  }
  result.settle_index = settle_index;
  // Before any observer runs: a report would read such a signal in place of the harness's row.
  for (const auto& o : observers) {
    for (const SignalInfo& signal : o->info().signals) {
      if (signal.kind == SignalKind::kEmbeddedError || signal.kind == SignalKind::kCanonicalError ||
          signal.kind == SignalKind::kCanonicalNorm) {
        throw InvalidInput("run_observers: " + o->name() + " publishes the signal '" + signal.name +
                           "' of a kind only the harness adds (the error and norm in the "
                           "observer's coordinates, from the truth)");
      }
    }
  }
  const long total = steps * static_cast<long>(observers.size());
  long done = 0;
  // Every observer's x̂ has the truth's size, or (without truth) the first observer's: the
  // reports lay the estimates side by side.
  Eigen::Index states = data.has_truth() ? data.x.rows() : 0;
  for (auto& observer : observers) {
    try {
      observer->reset();
    } catch (const InvalidInput&) {
      throw;
    } catch (...) {  // a user's observer that cannot start: nothing of it can run
      throw std::runtime_error("run_observers: observer '" + printable(observer->name()) +
                               "' threw in reset(): " + current_exception_text());
    }
    ObserverMetrics m;
    m.name = observer->name();
    m.engine = observer->info().engine;
    m.first_window_iterations = -1;
    // Read once: the table below is sized from it, whatever the observer does later.
    std::vector<SignalInfo> published = observer->info().signals;
    Eigen::MatrixXd estimate(states, steps);
    Eigen::MatrixXd signals(static_cast<Eigen::Index>(published.size()), steps);
    long iterations_sum = 0, evaluations_sum = 0;
    double elapsed_ns = 0.0;
    for (long k = 0; k < steps; ++k) {
      const Eigen::VectorXd y = data.y.col(k), u = data.u.col(k);
      // The first failing step's reason: the engine's (status, message, why not used) before
      // the observer's own, which often follows from it. Built once.
      const auto note_first = [&](const auto& why) {
        if (!m.first_failure.empty()) return;
        std::ostringstream os;
        os << "k = " << k << " (t = " << data.t[k] << "): " << why();
        m.first_failure = os.str();
      };
      const auto t0 = std::chrono::steady_clock::now();
      const ObserverStep* stepped = nullptr;
      try {
        stepped = &observer->step(k, data.t[k], y, u);
      } catch (const InvalidInput&) {
        throw;  // the observer refused the sample itself (its sizes): the caller's mistake
      } catch (...) {
        // A user's model, engine or observer threw (any type, `throw 42` too). Like any failed
        // step: counted, named in first_failure, the last good estimate kept, the run goes on
        // (the observer is stepped again at the next sample).
        elapsed_ns +=
            std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count();
        ++m.failures["observer_threw"];
        note_first([&] {
          std::string who = "observer '" + printable(m.name) + "'";
          if (!observer->info().model.empty()) {
            who += " on model '" + printable(observer->info().model) + "'";
          }
          return who + " threw: " + current_exception_text();
        });
        const auto hold = [k](Eigen::MatrixXd& columns) {  // the last good column, or NaN
          if (columns.rows() == 0) return;
          if (k > 0) {
            columns.col(k) = columns.col(k - 1);
          } else {
            columns.col(k).setConstant(std::numeric_limits<double>::quiet_NaN());
          }
        };
        hold(estimate);
        hold(signals);
        if (progress) progress(++done, total);
        continue;
      }
      const ObserverStep& s = *stepped;
      elapsed_ns +=
          std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count();
      if (states == 0) {  // the first observer without truth sets the size
        states = s.estimate.size();
        if (states == 0) {
          throw InvalidInput("run_observers: " + m.name +
                             " published an empty estimate at k = " + std::to_string(k));
        }
        // Samples before this one (steps that threw) have no estimate.
        estimate.setConstant(states, steps, std::numeric_limits<double>::quiet_NaN());
      }
      if (s.estimate.size() != estimate.rows() || s.signals.size() != signals.rows()) {
        // An observer of a user's own that breaks its promise: named, never written past.
        std::ostringstream os;
        os << "run_observers: " << m.name << " at sample k = " << k << " published an estimate of "
           << s.estimate.size() << " entries and " << s.signals.size() << " signals; expected "
           << estimate.rows() << " and " << signals.rows() << " (ObserverInfo::signals)";
        throw InvalidInput(os.str());
      }
      estimate.col(k) = s.estimate;
      if (signals.rows() > 0) signals.col(k) = s.signals;
      if (s.summary && !s.summary->usable()) {
        if (s.summary->converged()) ++m.failures["unusable"];
        note_first([&] {
          return s.summary->brief_report() +
                 (s.used_unusable_answer ? "; used though " : "; not used: ") +
                 s.summary->unusable_reason();
        });
      }
      if (s.measurement_missing) ++m.failures["missing_measurement"];
      if (!s.failure.empty()) {
        ++m.failures[s.failure];
        note_first([&] { return s.failure_message.empty() ? s.failure : s.failure_message; });
      }
      if (!s.estimate.allFinite()) {
        ++m.failures["non_finite_estimate"];
        note_first([&] { return m.name + ": the estimate is not finite"; });
      }
      if (s.summary) {
        ++m.solves;
        iterations_sum += s.summary->iterations;
        evaluations_sum += s.summary->function_evaluations;
        m.iterations_max = std::max(m.iterations_max, s.summary->iterations);
        if (m.first_window_iterations < 0) {
          m.first_window_iterations = s.summary->iterations;
          m.first_window = s.summary;
        }
        if (!s.summary->converged()) ++m.failures[std::string(to_string(s.summary->status))];
      }
      if (progress) progress(++done, total);
    }
    if (m.solves > 0) {
      m.iterations_mean = static_cast<double>(iterations_sum) / m.solves;
      m.evaluations_mean = static_cast<double>(evaluations_sum) / m.solves;
    }
    m.ns_per_step = steps > 0 ? elapsed_ns / static_cast<double>(steps) : 0.0;
    if (data.has_truth()) {
      m.mse = mean_squared_error(data.x, estimate, 0);
      m.mse_after_window = mean_squared_error(data.x, estimate, settle_index);
      m.max_error_after = max_abs_error(data.x, estimate, settle_index);
    }
    result.metrics.push_back(std::move(m));
    result.estimates.push_back(std::move(estimate));
    result.signals.push_back(std::move(signals));
    result.signal_info.push_back(std::move(published));
  }
  return result;
}

}  // namespace nlobs
