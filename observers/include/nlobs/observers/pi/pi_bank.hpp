#pragma once
// Banks of PI observers ([FFMG19], Remark 2 and eqs. 59–64): PI channels, algebraic signals
// and integrators that read each other's outputs, composed once and run as one ODE.
//
//   PiBank bank(/*outputs=*/1, /*inputs=*/1);
//   auto x2 = bank.add_pi("x2", {.measured = bank.output(0), .gains = {6, 25}});  // η = ẏ
//   auto x3 = bank.add_signal("x3", [=](const PiBank::Values& v) {
//     return sigma * alpha * v[u] / (g - v[x2.rate]); });                       // x3 from ẋ2
//   auto f = bank.add_pi("f", {.measured = x3, .a = -1.0,                      // f = −ẋ3 − σu
//                              .b = [=](const PiBank::Values& v) { return -sigma * v[u]; },
//                              .gains = {49, 700}});
//
// Each stage reads the measured outputs y, the inputs u, the time and the signals of the
// stages added before it (reading a later one is an error naming both). PiBankObserver runs
// a bank on samples, built as PiBankObserver(bank, PiBankOptions) with the bank in the model's
// place; docs/observers.md shows the three banks of the paper's examples.
#include <Eigen/Core>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "nlobs/observers/core/interval_integrator.hpp"
#include "nlobs/observers/core/observer.hpp"
#include "nlobs/observers/core/sampled_data.hpp"
#include "nlobs/observers/pi/pi_observer.hpp"

namespace nlobs {

class PiBank {
 public:
  struct Signal {
    int id = -1;
  };

  // What a stage function sees: y, u, t and the signals defined before the stage.
  class Values {
   public:
    double operator[](Signal s) const;
    double time() const { return data_[time_id_]; }

   private:
    friend class PiBank;
    const PiBank* bank_ = nullptr;
    const double* data_ = nullptr;
    int available_ = 0, reader_ = -1, time_id_ = 0;
  };
  using Function = std::function<double(const Values&)>;

  // η = a ṡ + b for the signal s = `measured`.
  struct Channel {
    Signal measured{};
    double a = 1.0;
    Function b = {};  // empty: b = 0
    PiGains gains{};
    // Start: γ(0) (the paper's choice is 0), or — when set — the γ(0) that makes
    // (η̂, η̂₁)(0) equal these at the first sample.
    Eigen::Vector2d gamma0 = Eigen::Vector2d::Zero();
    std::optional<Eigen::Vector2d> initial_estimates{};
  };
  struct PiOutputs {
    Signal eta;   // η̂, named "<name>"
    Signal rate;  // η̂₁ (→ η̇), named "<name>.rate"
  };

  PiBank(Eigen::Index outputs, Eigen::Index inputs);

  Signal output(Eigen::Index i = 0) const;  // y_i
  Signal input(Eigen::Index i = 0) const;   // u_i
  Signal time() const { return Signal{static_cast<int>(outputs_ + inputs_)}; }

  PiOutputs add_pi(const std::string& name, Channel channel);
  Signal add_signal(const std::string& name, Function value);
  // x' = rate(values), x(0) = initial (e.g. x̂1' = η̂₁ + b y of the Chua example).
  Signal add_integrator(const std::string& name, Function rate, double initial = 0.0);

  Eigen::Index outputs() const { return outputs_; }
  Eigen::Index inputs() const { return inputs_; }
  Eigen::Index state_size() const { return state_size_; }
  Eigen::Index signal_count() const { return static_cast<Eigen::Index>(names_.size()); }
  const std::string& signal_name(Signal s) const;
  // The signals the stages define (all but y, u, t), in order.
  std::vector<Signal> stage_signals() const;

  struct ChannelInfo {
    std::string name;
    PiGains gains;
    double a;
  };
  std::vector<ChannelInfo> channels() const;

  // The state at the first sample (needs y, u for channels started from estimates).
  Eigen::VectorXd initial_state(double t, const Eigen::VectorXd& y, const Eigen::VectorXd& u) const;
  // Every signal at (t, y, u, state) into `signals` (size signal_count()) and, when `rate` is
  // given, d state/dt. Returns the first non-finite stage signal, or Signal{-1}. Allocates
  // nothing once the outputs have their size.
  Signal evaluate(double t, const Eigen::VectorXd& y, const Eigen::VectorXd& u,
                  const Eigen::VectorXd& state, Eigen::VectorXd& signals,
                  Eigen::VectorXd* rate) const;

 private:
  enum class Kind { kPi, kSignal, kIntegrator };
  struct Stage {
    Kind kind;
    std::string name;
    Channel channel;  // kPi
    Function fn;      // kSignal: value; kIntegrator: rate
    double initial = 0.0;
    int state = 0;      // first state index
    int signal = 0;     // first output signal
    int available = 0;  // signals readable by this stage
  };
  Signal add_name(const std::string& name);
  Values view(const double* data, int available, int reader) const;
  void check_readable(Signal s, const std::string& stage) const;

  Eigen::Index outputs_, inputs_, state_size_ = 0;
  std::vector<std::string> names_;
  std::vector<Stage> stages_;
  friend class Values;
};

// A bank observer's options: the name, the signals that form x̂ and the time stepping. Unlike
// the other observers' options there is no initial_estimate: a bank's state is its stages'
// (γ, integrals), so its start stays with them, in each channel's gamma0 / initial_estimates
// and each integrator's initial value, where the stage that uses it is defined.
struct PiBankOptions {
  std::string name = "pi_bank";            // in reports
  std::vector<PiBank::Signal> estimate{};  // the signals that form x̂, in the model's state order
  double sample_time = 0.0;                // seconds between samples k and k + 1 (> 0)
  int substeps = 1;                        // RK4 steps per sample interval
  // Throws InvalidInput naming the field and value: an empty name, an empty estimate or one
  // holding an invalid signal (id < 0, e.g. a default Signal{}), a sample_time not finite and
  // > 0, substeps < 1. Whether each signal is one of the bank's, only the constructor can tell.
  void validate() const;
};

// Runs a bank on samples y_k, u_k placed by their time on the grid t_0 + m·T, as every
// sampled-data observer does (sampled_data.hpp): between samples y is interpolated linearly (the
// interval [t_{k−1}, t_k] is integrated by RK4 when y_k arrives, so x̂_k uses data up to t_k) and u
// is held (the plant's sampled input). A non-finite y_k is skipped with the state held, a
// non-finite u_k reported with the state held; the next good sample integrates across the gap (y
// interpolated, u held, the same step length). A step whose signals turn non-finite (a stage left
// its domain) keeps the last good state and reports the signal and time, and the sample is dropped
// as if missing; a first sample whose signals are not finite does not start the bank. Built as
// PiBankObserver(bank, PiBankOptions) like every observer, the bank playing the model's part:
// PiBankOptions::validate() (called by the constructor) checks the options alone, the constructor
// that each estimate signal is one of the bank's and, by one evaluation on zeros, that no stage
// reads a later one.
class PiBankObserver final : public Observer {
 public:
  PiBankObserver(PiBank bank, PiBankOptions options);
  void reset() override;
  const ObserverStep& step(long k, double t, const Eigen::VectorXd& y,
                           const Eigen::VectorXd& u) override;
  const PiBank& bank() const { return bank_; }

 private:
  // [t0, t1] (interval_integrator.hpp), then the signals at t1 (y1, u1); false, state_
  // untouched, when a signal is not finite on the way or at t1.
  bool integrate(double t0, double t1, const Eigen::VectorXd& y1, const Eigen::VectorXd& u1);
  // The bank's rate at (t, s) with y(t) interpolated and u held; false at a non-finite signal.
  bool rate(double t, const double* s, double* ds);
  void publish();

  PiBank bank_;
  PiBankOptions options_;                  // validated; options_.estimate are the bank's signals
  std::vector<PiBank::Signal> published_;  // the stage signals, as ObserverInfo::signals
  // y between samples: the line through the last two good ones.
  SampledData<Eigen::Dynamic, Eigen::Dynamic> clock_;
  std::optional<IntervalIntegrator> interval_;
  Eigen::VectorXd state_, signals_, y_, x_, dx_;
  std::vector<double> trial_;
  PiBank::Signal bad_{};
  double bad_t_ = 0.0;
  ObserverStep step_;
};

}  // namespace nlobs
