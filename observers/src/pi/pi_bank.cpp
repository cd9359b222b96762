#include "nlobs/observers/pi/pi_bank.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "nlobs/observers/core/option_checks.hpp"
#include "nlobs/solvers/status.hpp"

namespace nlobs {

double PiBank::Values::operator[](Signal s) const {
  if (s.id < 0 || s.id >= available_) bank_->check_readable(s, bank_->stages_[reader_].name);
  return data_[s.id];
}

PiBank::PiBank(Eigen::Index outputs, Eigen::Index inputs) : outputs_(outputs), inputs_(inputs) {
  if (outputs < 1 || inputs < 0) {
    throw InvalidInput("PiBank: needs at least one output and a non-negative number of inputs");
  }
  // (Appending rather than "y" + to_string(): GCC 12 reports a false -Wrestrict on the latter.)
  const auto numbered = [](char letter, Eigen::Index i) {
    std::string name(1, letter);
    name.append(std::to_string(i + 1));
    return name;
  };
  for (Eigen::Index i = 0; i < outputs; ++i) names_.push_back(numbered('y', i));
  for (Eigen::Index i = 0; i < inputs; ++i) names_.push_back(numbered('u', i));
  names_.push_back("t");
}

PiBank::Signal PiBank::output(Eigen::Index i) const {
  if (i < 0 || i >= outputs_) {
    throw InvalidInput("PiBank::output: index " + std::to_string(i) + " outside 0.." +
                       std::to_string(outputs_ - 1));
  }
  return Signal{static_cast<int>(i)};
}

PiBank::Signal PiBank::input(Eigen::Index i) const {
  if (i < 0 || i >= inputs_) {
    throw InvalidInput("PiBank::input: index " + std::to_string(i) + " outside the " +
                       std::to_string(inputs_) + " inputs");
  }
  return Signal{static_cast<int>(outputs_ + i)};
}

const std::string& PiBank::signal_name(Signal s) const {
  if (s.id < 0 || s.id >= signal_count()) {
    throw InvalidInput("PiBank: signal " + std::to_string(s.id) + " does not exist");
  }
  return names_[static_cast<size_t>(s.id)];
}

void PiBank::check_readable(Signal s, const std::string& stage) const {
  std::ostringstream os;
  os << "PiBank: stage '" << stage << "' reads ";
  if (s.id < 0 || s.id >= signal_count()) {
    os << "signal " << s.id << ", which does not exist";
  } else {
    os << "'" << names_[static_cast<size_t>(s.id)]
       << "', which is defined by a later stage (or the stage itself); a stage reads y, u, t "
          "and the stages added before it";
  }
  throw InvalidInput(os.str());
}

PiBank::Signal PiBank::add_name(const std::string& name) {
  if (name.empty()) throw InvalidInput("PiBank: a stage needs a name");
  for (const auto& n : names_) {
    if (n == name) throw InvalidInput("PiBank: a signal named '" + name + "' exists already");
  }
  names_.push_back(name);
  return Signal{static_cast<int>(names_.size()) - 1};
}

PiBank::PiOutputs PiBank::add_pi(const std::string& name, Channel c) {
  validate(c.gains, "PiBank channel '" + name + "'");
  if (!std::isfinite(c.a) || c.a == 0.0) {
    throw InvalidInput("PiBank channel '" + name +
                       "': a must be finite and non-zero (eta = a ds/dt + b)");
  }
  if (!c.gamma0.allFinite() || (c.initial_estimates && !c.initial_estimates->allFinite())) {
    throw InvalidInput("PiBank channel '" + name + "': initial values must be finite");
  }
  const int available = static_cast<int>(names_.size());
  if (c.measured.id < 0 || c.measured.id >= available) check_readable(c.measured, name);
  for (const auto& n : names_) {  // both names free before either is taken
    if (n == name + ".rate")
      throw InvalidInput("PiBank: a signal named '" + n + "' exists already");
  }
  Stage s{Kind::kPi, name, std::move(c), {}, 0.0, static_cast<int>(state_size_), 0, available};
  const Signal eta = add_name(name);
  const Signal rate = add_name(name + ".rate");
  s.signal = eta.id;
  state_size_ += 2;
  stages_.push_back(std::move(s));
  return {eta, rate};
}

PiBank::Signal PiBank::add_signal(const std::string& name, Function value) {
  if (!value) throw InvalidInput("PiBank signal '" + name + "': needs a function");
  const int available = static_cast<int>(names_.size());
  const Signal id = add_name(name);
  stages_.push_back(Stage{Kind::kSignal, name, {}, std::move(value), 0.0, 0, id.id, available});
  return id;
}

PiBank::Signal PiBank::add_integrator(const std::string& name, Function rate, double initial) {
  if (!rate) throw InvalidInput("PiBank integrator '" + name + "': needs a rate function");
  if (!std::isfinite(initial)) {
    throw InvalidInput("PiBank integrator '" + name + "': initial value must be finite");
  }
  const int available = static_cast<int>(names_.size());
  const Signal id = add_name(name);
  stages_.push_back(Stage{Kind::kIntegrator,
                          name,
                          {},
                          std::move(rate),
                          initial,
                          static_cast<int>(state_size_),
                          id.id,
                          available});
  state_size_ += 1;
  return id;
}

std::vector<PiBank::Signal> PiBank::stage_signals() const {
  std::vector<Signal> out;
  for (int i = static_cast<int>(outputs_ + inputs_) + 1; i < signal_count(); ++i) {
    out.push_back(Signal{i});
  }
  return out;
}

std::vector<PiBank::ChannelInfo> PiBank::channels() const {
  std::vector<ChannelInfo> out;
  for (const Stage& s : stages_) {
    if (s.kind == Kind::kPi) out.push_back({s.name, s.channel.gains, s.channel.a});
  }
  return out;
}

PiBank::Values PiBank::view(const double* data, int available, int reader) const {
  Values v;
  v.bank_ = this;
  v.data_ = data;
  v.available_ = available;
  v.reader_ = reader;
  v.time_id_ = static_cast<int>(outputs_ + inputs_);
  return v;
}

Eigen::VectorXd PiBank::initial_state(double t, const Eigen::VectorXd& y,
                                      const Eigen::VectorXd& u) const {
  Eigen::VectorXd state = Eigen::VectorXd::Zero(state_size_);
  for (const Stage& s : stages_) {
    if (s.kind == Kind::kPi) state.segment<2>(s.state) = s.channel.gamma0;
    if (s.kind == Kind::kIntegrator) state[s.state] = s.initial;
  }
  // Channels started from estimates need their measured signal at t0, which may depend on
  // earlier stages: evaluate in order, fixing each channel's γ(0) before later stages read it.
  Eigen::VectorXd signals(signal_count());
  for (size_t i = 0; i < stages_.size(); ++i) {
    const Stage& s = stages_[i];
    if (s.kind != Kind::kPi || !s.channel.initial_estimates) continue;
    evaluate(t, y, u, state, signals, nullptr);
    const PiChannelConstants c{s.channel.gains, s.channel.a};
    state.segment<2>(s.state) =
        pi_gamma_for(c, *s.channel.initial_estimates, signals[s.channel.measured.id]);
  }
  return state;
}

PiBank::Signal PiBank::evaluate(double t, const Eigen::VectorXd& y, const Eigen::VectorXd& u,
                                const Eigen::VectorXd& state, Eigen::VectorXd& signals,
                                Eigen::VectorXd* rate) const {
  if (y.size() != outputs_ || u.size() != inputs_ || state.size() != state_size_) {
    std::ostringstream os;
    os << "PiBank::evaluate: expected " << outputs_ << " outputs, " << inputs_ << " inputs and "
       << state_size_ << " states, got " << y.size() << ", " << u.size() << ", " << state.size();
    throw InvalidInput(os.str());
  }
  signals.resize(signal_count());
  if (rate) rate->resize(state_size_);
  signals.head(outputs_) = y;
  signals.segment(outputs_, inputs_) = u;
  signals[outputs_ + inputs_] = t;
  Signal bad{-1};
  for (size_t i = 0; i < stages_.size(); ++i) {
    const Stage& s = stages_[i];
    const Values v = view(signals.data(), s.available, static_cast<int>(i));
    switch (s.kind) {
      case Kind::kPi: {
        const PiChannelConstants c{s.channel.gains, s.channel.a};
        const double measured = signals[s.channel.measured.id];
        const double b = s.channel.b ? s.channel.b(v) : 0.0;
        const Eigen::Vector2d gamma = state.segment<2>(s.state);
        signals.segment<2>(s.signal) = pi_estimates(c, gamma, measured);
        if (rate) rate->segment<2>(s.state) = pi_gamma_rate(c, gamma, measured, b);
        if (bad.id < 0 && !std::isfinite(b)) bad = Signal{s.signal};
        break;
      }
      case Kind::kSignal:
        signals[s.signal] = s.fn(v);
        break;
      case Kind::kIntegrator:
        signals[s.signal] = state[s.state];
        if (rate) (*rate)[s.state] = s.fn(v);
        if (rate && bad.id < 0 && !std::isfinite((*rate)[s.state])) bad = Signal{s.signal};
        break;
    }
    if (bad.id < 0) {
      const int count = s.kind == Kind::kPi ? 2 : 1;
      for (int j = 0; j < count; ++j) {
        if (!std::isfinite(signals[s.signal + j])) {
          bad = Signal{s.signal + j};
          break;
        }
      }
    }
  }
  return bad;
}

// ---------------------------------------------------------------------------------------------

namespace {

// "estimate[i]", appended piecewise: GCC 12's false -Wrestrict, as in PiBank().
std::string estimate_field(size_t i) {
  std::string field = "estimate[";
  field.append(std::to_string(i)).append("]");
  return field;
}

}  // namespace

void PiBankOptions::validate() const {
  detail::require_name("PiBankOptions", name);
  if (estimate.empty()) {
    detail::invalid_option("PiBankOptions", "estimate", "list at least one signal", "{}");
  }
  for (size_t i = 0; i < estimate.size(); ++i) {
    if (estimate[i].id < 0) {
      detail::invalid_option("PiBankOptions", estimate_field(i).c_str(), "be a signal id >= 0",
                             std::to_string(estimate[i].id));
    }
  }
  detail::require_positive("PiBankOptions", "sample_time", sample_time);
  detail::require_at_least("PiBankOptions", "substeps", static_cast<long>(substeps), 1L);
}

PiBankObserver::PiBankObserver(PiBank bank, PiBankOptions options)
    : bank_(std::move(bank)),
      options_(detail::validated(std::move(options))),
      clock_(bank_.outputs(), bank_.inputs(), options_.sample_time, /*points=*/2) {
  for (size_t i = 0; i < options_.estimate.size(); ++i) {
    const int id = options_.estimate[i].id;  // >= 0: validated
    if (id >= bank_.signal_count()) {
      detail::invalid_option(
          "PiBankOptions", estimate_field(i).c_str(),
          "be one of the bank's " + std::to_string(bank_.signal_count()) + " signals",
          "signal " + std::to_string(id));
    }
  }
  published_ = bank_.stage_signals();
  info_.name = options_.name;
  for (const PiBank::Signal s : published_) info_.signals.push_back({bank_.signal_name(s)});
  const Eigen::Index n = bank_.state_size();
  for (Eigen::VectorXd* v : {&state_, &x_, &dx_}) v->resize(n);
  trial_.resize(static_cast<size_t>(n));
  signals_.resize(bank_.signal_count());
  y_.resize(bank_.outputs());
  IntervalIntegratorOptions o;  // classic RK4, `substeps` per interval
  o.sample_time = options_.sample_time;
  o.substeps = options_.substeps;
  interval_.emplace(
      static_cast<int>(n), [this](double t, const double* s, double* ds) { return rate(t, s, ds); },
      o);
  step_.estimate.resize(static_cast<Eigen::Index>(options_.estimate.size()));
  step_.signals.resize(static_cast<Eigen::Index>(published_.size()));
  // A dry evaluation: a stage reading a later signal fails here, at construction.
  bank_.evaluate(0.0, Eigen::VectorXd::Zero(bank_.outputs()), Eigen::VectorXd::Zero(bank_.inputs()),
                 Eigen::VectorXd::Zero(n), signals_, &dx_);
  reset();
}

void PiBankObserver::reset() {
  clock_.reset();
  step_.estimate.setConstant(std::nan(""));
  step_.signals.setConstant(std::nan(""));
}

void PiBankObserver::publish() {
  for (size_t i = 0; i < options_.estimate.size(); ++i) {
    step_.estimate[static_cast<Eigen::Index>(i)] = signals_[options_.estimate[i].id];
  }
  for (size_t i = 0; i < published_.size(); ++i) {
    step_.signals[static_cast<Eigen::Index>(i)] = signals_[published_[i].id];
  }
}

bool PiBankObserver::rate(double t, const double* s, double* ds) {
  const Eigen::Index n = bank_.state_size();
  x_ = Eigen::Map<const Eigen::VectorXd>(s, n);
  clock_.output_at(t, y_);
  const PiBank::Signal bad = bank_.evaluate(t, y_, clock_.held_input(), x_, signals_, &dx_);
  if (bad.id >= 0) {
    bad_ = bad;
    bad_t_ = t;
    return false;
  }
  Eigen::Map<Eigen::VectorXd>(ds, n) = dx_;
  return true;
}

bool PiBankObserver::integrate(double t0, double t1, const Eigen::VectorXd& y1,
                               const Eigen::VectorXd& u1) {
  Eigen::Map<Eigen::VectorXd>(trial_.data(), state_.size()) = state_;
  if (!interval_->integrate(t0, t1, trial_)) return false;  // bad_, bad_t_ set by rate()
  x_ = Eigen::Map<const Eigen::VectorXd>(trial_.data(), state_.size());
  if (!x_.allFinite()) {
    bad_ = PiBank::Signal{-1};
    bad_t_ = t1;
    return false;
  }
  // The signals at t1 from the new state, as they will be published: a bank of signals only
  // (nothing to integrate) or one whose signals leave their domain exactly at t1 fails here.
  const PiBank::Signal bad = bank_.evaluate(t1, y1, u1, x_, signals_, nullptr);
  if (bad.id >= 0) {
    bad_ = bad;
    bad_t_ = t1;
    return false;
  }
  state_ = x_;
  return true;
}

const ObserverStep& PiBankObserver::step(long k, double t, const Eigen::VectorXd& y,
                                         const Eigen::VectorXd& u) {
  step_.ready = clock_.started();
  switch (clock_.receive(options_.name, k, t, y, u, step_)) {
    case SampledData<Eigen::Dynamic, Eigen::Dynamic>::kHold:
      return step_;  // the integral states keep their value
    case SampledData<Eigen::Dynamic, Eigen::Dynamic>::kStart: {
      const double t0 = clock_.time();  // the grid time of t
      state_ = bank_.initial_state(t0, y, u);
      const PiBank::Signal bad = bank_.evaluate(t0, y, u, state_, signals_, nullptr);
      if (bad.id >= 0 || !state_.allFinite()) {  // not started: try again at the next sample
        std::ostringstream os;
        os << options_.name << ": cannot start at t = " << t0 << ": signal '"
           << (bad.id >= 0 ? bank_.signal_name(bad) : std::string("state")) << "' is not finite";
        clock_.reject(step_, os.str());
        return step_;
      }
      break;
    }
    case SampledData<Eigen::Dynamic, Eigen::Dynamic>::kIntegrate:
      if (!integrate(clock_.last_time(), clock_.time(), y, u)) {
        std::ostringstream os;
        os << options_.name << ": ";
        if (bad_.id >= 0) {
          os << "signal '" << bank_.signal_name(bad_) << "' is not finite at t = " << bad_t_;
        } else {
          os << "the state became non-finite by t = " << bad_t_;
        }
        os << "; kept the estimate of t = " << clock_.last_time();
        clock_.reject(step_, os.str());  // the next sample goes on from the last good state
        return step_;
      }
      break;
  }
  clock_.accept();
  step_.ready = true;
  publish();
  return step_;
}

}  // namespace nlobs
