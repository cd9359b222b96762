#pragma once
// Window estimator = any engine × any output window ([MGFF23]). Once the window of N samples
// is full, at each k it solves for w = x̂[k−N+1] and outputs x̂[k] = f^{N−1}(w*):
//   square window (N·p = n): G(w) = w + Ψ (Y − H(w)) with any engine (Picard, Aitken,
//     Steffensen, Anderson, Newton, Ceres, NLopt); Ψ = I is the paper's form, Ψ = (∂H/∂w)⁻¹
//     (the chord form of the Newton observer) makes G contract wherever ∂H/∂w is invertible;
//   longer window (N·p > n): min ½‖Y − H(w)‖² with a least-squares engine (Ceres, NLopt).
// A solve's answer is used only when its Summary is usable() (the solver layer's one policy).
// Otherwise — and before the window is full, and at a missing (non-finite) measurement — the
// estimate coasts on the model, x̂[k] = f(x̂[k−1], u[k−1], k−1), from the initial guess at
// k = 0; the next solve starts from the coasted estimate of its first sample (never from the
// answer of a failed solve), so a run that fails is retried at every sample and recovers once
// the data allow. After a missing sample the window refills from scratch. Samples are placed
// by their time on the model's grid (SampleClock): a skipped grid point is a missing sample, a
// sample off the grid is refused (failure "non_uniform": the window map assumes the grid). The
// estimate is never non-finite: a coasting step that overflows keeps the last finite estimate and
// marks the step (failure "non_finite_estimate"). Warm start of a solve that follows a usable one:
// the previous solution w* (the paper's choice) or its propagation f(w*) to the next window's first
// sample (measured better; the default, docs/observers.md). The engine's Summary of each solve is
// exposed per step.
//
//   auto estimator = make_window_estimator(model, "newton:tol=1e-10", options);  // by spec, or
//   WindowEstimator<Model> estimator(model, options, std::make_unique<CeresEngine<3>>(...));
#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/QR>
#include <cmath>
#include <memory>
#include <sstream>
#include <string>
#include <string_view>

#include "nlobs/observers/core/chi_squared.hpp"
#include "nlobs/observers/core/observer.hpp"
#include "nlobs/observers/core/option_checks.hpp"
#include "nlobs/observers/core/sample_clock.hpp"
#include "nlobs/observers/window/output_window.hpp"
#include "nlobs/observers/window/window_problems.hpp"
#include "nlobs/solvers/engine.hpp"
#include "nlobs/solvers/engine_registry.hpp"
#include "nlobs/solvers/spectral_radius.hpp"

namespace nlobs {

enum class WarmStart {
  kPrevious,    // w0 = w* of the previous window (the paper)
  kPropagated,  // w0 = f(w*): the previous solution moved to the new window's first sample
};

// Ψ of the square window's G(w) = w + Ψ (Y − H(w)) (docs/observers.md, "When fixed-point
// engines apply"). Picard-type engines converge near w* only when ρ(I − Ψ ∂H/∂w) < 1.
enum class WindowGain {
  kAuto,      // engines that need a contraction: identity when ρ(I − ∂H/∂w) < 1 at the first
              // window's guess, else newton (with a warning); every other engine: identity
  kIdentity,  // Ψ = I, the paper's form (a warning when it does not contract at the first window)
  kScalar,    // Ψ = gain_scale · I
  kNewton,  // Ψ = (∂H/∂w)⁻¹ at the guess, kept across windows and refreshed when a solve's
            // contraction estimate reaches 1 or a solve is not usable (chord Newton)
};

std::string_view to_string(WindowGain gain);

struct WindowEstimatorOptions {
  // Name in reports; empty: "window:<engine label>", with ",N=<N>" for a longer window.
  std::string name;
  // x̂[0], and the first window's guess for w = x̂[k−N+1]: n finite numbers (required).
  Eigen::VectorXd initial_estimate;
  Eigen::Index window = 0;  // N; 0 = the square window n / p
  WarmStart warm_start = WarmStart::kPropagated;
  WindowGain gain = WindowGain::kAuto;  // Ψ (square windows only)
  double gain_scale = 1.0;              // Ψ = gain_scale · I for WindowGain::kScalar
  // The noise the outputs are declared to carry, R (p × p; symmetric positive definite), for the
  // consistency check of a least-squares window (N·p > n). With the model right over the window
  // (no process noise) and the noise Gaussian, the R-weighted cost at its minimiser,
  //   2V = ‖(I − P) z‖²,  z = L⁻¹ (Y − H(w*)) sample by sample (R = L Lᵀ),
  //   P the projector on the range of L⁻¹ ∂H/∂w(w*),
  // follows χ² with N·p − n degrees of freedom (exactly for a linear model, to first order
  // otherwise) [BSLK01]. The projection removes what one more Gauss–Newton step in the R
  // metric would still fit, so the statistic is the weighted minimiser's even when the engine
  // minimised the unweighted cost or stopped at its tolerance short of the minimum — when that
  // step is small (‖δ‖∞ ≤ 1e-2 (1 + ‖w*‖∞)); a larger one is no refinement of the answer (a
  // flat local minimum, where ∂H/∂w nearly vanishes), and 2V is then ‖z‖². An answer
  // with 2V above that χ²'s `consistency_quantile` is refused — failure
  // "inconsistent_with_noise", the estimate coasts as after an unusable solve — rather than
  // published: a local minimum, or a model that does not fit the data. Empty: not checked. A
  // square window (N·p = n) fits any data exactly and is never checked.
  Eigen::MatrixXd measurement_covariance;
  // In (0, 1): the share of consistent answers the check lets through; 1 − it is the rate of
  // false refusals when everything is right (one window in 10 000 by default: a refusal coasts
  // the estimate, which costs on a chaotic plant, and the local minima the check is for sit
  // orders of magnitude above any quantile — 2V ≈ 4.5e4 against 23.5 in the tests).
  double consistency_quantile = 0.9999;
  // The engine records its trace (Summary::trace, the convergence plot's data) on the first
  // window after each reset only: Engine::set_record_trace around that one solve, so that every
  // other step stays lean.
  bool trace_first_window = false;
  // Throws InvalidInput naming the field for a negative window, a gain_scale that is 0 or not
  // finite, an initial estimate that is empty or not finite, a measurement_covariance given but
  // not symmetric positive definite, or a consistency_quantile outside (0, 1). The constructor
  // calls it and checks the sizes against the model.
  void validate() const;
};

template <DiscreteModel Model>
class WindowEstimator final : public Observer {
 public:
  static constexpr int N = Model::kStates;
  using State = Vector<N>;
  using Gain = Matrix<N, N>;

  // Throws InvalidInput for invalid options, a window that cannot determine the state, an
  // initial estimate of the wrong size, a missing engine, or a square-system engine on a longer
  // window. The engine's label() (its spec when it came from the registry) names it in reports.
  WindowEstimator(Model model, WindowEstimatorOptions options, std::unique_ptr<Engine<N>> engine);

  // An engine of its own for the first window after each reset only (a first window solved
  // differently; for its trace alone, WindowEstimatorOptions::trace_first_window needs none).
  void set_first_window_engine(std::unique_ptr<Engine<N>> engine) {
    first_engine_ = std::move(engine);
  }
  const OutputWindow<Model>& output_window() const { return state_->window; }
  const WindowEstimatorOptions& options() const { return options_; }
  // Ψ in use (kAuto until the first window decides it).
  WindowGain gain() const { return active_gain_; }

  void reset() override;
  const ObserverStep& step(long k, double t, const Eigen::VectorXd& y,
                           const Eigen::VectorXd& u) override;

 private:
  struct Shared {
    Shared(Model m, Eigen::Index length) : window(std::move(m), length) {}
    OutputWindow<Model> window;
    Gain gain;  // Ψ, read by the gain problem at every evaluation
  };

  static Eigen::Index window_length(const Model& model, const WindowEstimatorOptions& o) {
    o.validate();
    if (o.window > 0) return o.window;
    const Eigen::Index n = model.states(), p = model.outputs();
    return (n + p - 1) / p;  // the square window when p divides n
  }

  void require_least_squares_engine() const;
  // The estimate kept for the window's first sample k − N + 1 (k the model index), coasted on
  // the model; `moved`: k is not the first sample.
  State coasted_guess(long k, bool moved) const;
  // The entry of history_ for model index k (any sign).
  std::size_t slot(long k) const {
    const long length = static_cast<long>(state_->window.length());
    return static_cast<std::size_t>(((k % length) + length) % length);
  }
  Summary solve_window(Engine<N>& engine, State& w, long k);
  Summary solve_once(Engine<N>& engine, State& w);
  void choose_gain(const Engine<N>& engine, const State& w, long k);
  // False, with the step's failure set, when a least-squares window's answer w is inconsistent
  // with the declared noise (WindowEstimatorOptions::measurement_covariance); true otherwise.
  bool consistent_with_noise(const State& w, long k);
  // Ψ = (∂H/∂w)⁻¹ at w; false (Ψ unchanged) where ∂H/∂w is singular or not finite.
  bool refresh_newton_gain(const State& w);
  bool window_jacobian(const State& w, Gain& dh) const;  // dh = ∂H/∂w

  WindowEstimatorOptions options_;
  std::unique_ptr<Engine<N>> engine_;
  std::string spec_;
  State initial_guess_;
  std::unique_ptr<Shared> state_;
  std::unique_ptr<FixedPointProblem<N>> fixed_point_;   // Ψ = I
  std::unique_ptr<FixedPointProblem<N>> gain_point_;    // Ψ = state_->gain
  std::unique_ptr<RootProblem<N, N>> square_residual_;  // Y − H(w): ∂H/∂w for Ψ
  std::unique_ptr<RootProblem<N, Dynamic>> root_;
  bool square_ = true;
  ObserverStep step_;
  SampleClock clock_;
  State coast_, next_guess_;
  Eigen::VectorXd last_u_;
  std::vector<State> history_;  // estimates of the last N samples, by k mod N
  bool have_solution_ = false;
  std::unique_ptr<Engine<N>> first_engine_;
  bool solved_once_ = false;
  WindowGain active_gain_ = WindowGain::kAuto;
  bool gain_stale_ = true;          // newton: refresh Ψ before the next solve
  bool gain_valid_ = false;         // newton: Ψ was formed at least once
  bool gain_chosen_ = false;        // the first window decided Ψ (kAuto) and checked it
  std::size_t setup_warnings_ = 0;  // info_.warnings from the constructor
  bool warned_singular_ = false;
  // The consistency check: R = L Lᵀ, the χ² quantile 2V is held to, and its buffers (sized once,
  // the QR's at its first use; a model of run-time size also allocates the step δ's n entries
  // per check).
  bool check_consistency_ = false;
  Eigen::LLT<Eigen::MatrixXd> noise_factor_;
  double consistency_bound_ = 0.0;
  Eigen::VectorXd predicted_, whitened_, householder_workspace_;
  typename RootProblem<N, Dynamic>::JacobianType window_jacobian_;  // ∂F/∂w, F = Y − H
  Eigen::HouseholderQR<typename RootProblem<N, Dynamic>::JacobianType> projection_;
  // Relative offset of a guess at a singular point of the window map; an LU pivot below this
  // fraction of the largest |∂H/∂w| entry counts as zero (as in NewtonEngine).
  static constexpr double kPerturbation = 1e-3;
  static constexpr double kSingularPivot = 1e-13;
  // The largest Gauss–Newton step, relative to 1 + ‖w*‖∞, whose fit the consistency check
  // credits to the answer (consistent_with_noise).
  static constexpr double kLargestRefinement = 1e-2;
};

// The one-line form: the engine named by a spec of EngineRegistry<N> ("newton:tol=1e-10"),
// `base` supplying the stop criteria the spec does not set. Throws InvalidInput for an unknown
// engine or option and everything the constructor refuses.
template <DiscreteModel Model>
std::unique_ptr<WindowEstimator<Model>> make_window_estimator(Model model,
                                                              std::string_view engine_spec,
                                                              WindowEstimatorOptions options,
                                                              SolverOptions base = {}) {
  auto engine = EngineRegistry<Model::kStates>::global().create(engine_spec, std::move(base));
  return std::make_unique<WindowEstimator<Model>>(std::move(model), std::move(options),
                                                  std::move(engine));
}

template <DiscreteModel Model>
WindowEstimator<Model>::WindowEstimator(Model model, WindowEstimatorOptions options,
                                        std::unique_ptr<Engine<N>> engine)
    : options_(std::move(options)),
      engine_(std::move(engine)),
      state_(std::make_unique<Shared>(std::move(model), window_length(model, options_))),
      clock_(SampleClock::of(state_->window.model(), "the window map assumes samples on the grid",
                             false)) {
  if (!engine_) throw InvalidInput("WindowEstimator: no engine");
  spec_ = engine_->label();
  const Eigen::Index n = state_->window.states();
  if (options_.initial_estimate.size() != n) {
    std::ostringstream os;
    os << "WindowEstimatorOptions::initial_estimate has " << options_.initial_estimate.size()
       << " entries; the model has " << n << " states";
    throw InvalidInput(os.str());
  }
  initial_guess_ = options_.initial_estimate;
  if (options_.measurement_covariance.size()) {
    const Eigen::Index p = state_->window.model().outputs();
    detail::require_shape("WindowEstimatorOptions", "measurement_covariance",
                          options_.measurement_covariance, p, p);
  }
  square_ = state_->window.rows() == n;
  // Built once; they read the window, which never moves (it lives behind a unique_ptr).
  if (square_) {
    state_->gain = Gain::Identity(n, n);
    fixed_point_ = std::make_unique<FixedPointProblem<N>>(square_window_problem(state_->window));
    gain_point_ = std::make_unique<FixedPointProblem<N>>(
        square_window_problem(state_->window, &state_->gain));
    square_residual_ = std::make_unique<RootProblem<N, N>>(square_window_residual(state_->window));
  } else {
    require_least_squares_engine();
    if (options_.gain == WindowGain::kScalar || options_.gain == WindowGain::kNewton) {
      throw InvalidInput("WindowEstimatorOptions::gain = " + std::string(to_string(options_.gain)) +
                         " applies to square windows (N*p = n); a window of N = " +
                         std::to_string(state_->window.length()) +
                         " is solved in the least-squares sense, without Psi");
    }
    root_ = std::make_unique<RootProblem<N, Dynamic>>(window_residual_problem(state_->window));
    if (options_.measurement_covariance.size()) {
      const Eigen::Index rows = state_->window.rows();
      noise_factor_.compute(options_.measurement_covariance);
      consistency_bound_ =
          chi_squared_quantile(static_cast<double>(rows - n), options_.consistency_quantile);
      predicted_.resize(rows);
      whitened_.resize(rows);
      householder_workspace_.resize(1);
      window_jacobian_.resize(rows, n);
      check_consistency_ = true;
    }
  }
  info_.engine = spec_;
  info_.window = state_->window.length();
  info_.name = options_.name;
  if (info_.name.empty()) {
    info_.name = "window:" + spec_;
    if (!square_) info_.name += ",N=" + std::to_string(state_->window.length());
  }
  setup_warnings_ = info_.warnings.size();
  reset();
}

template <DiscreteModel Model>
void WindowEstimator<Model>::reset() {
  state_->window.clear();
  clock_.reset();
  step_ = ObserverStep{};
  coast_ = initial_guess_;
  history_.assign(static_cast<size_t>(state_->window.length()), initial_guess_);
  have_solution_ = false;
  solved_once_ = false;
  active_gain_ = options_.gain;
  gain_stale_ = true;
  gain_valid_ = false;
  gain_chosen_ = false;
  warned_singular_ = false;
  info_.warnings.resize(setup_warnings_);  // what the last run found goes, the set-up's stays
  if (square_) {
    const Eigen::Index n = state_->window.states();
    state_->gain = options_.gain == WindowGain::kScalar
                       ? Gain(options_.gain_scale * Gain::Identity(n, n))
                       : Gain(Gain::Identity(n, n));
  }
}

template <DiscreteModel Model>
const ObserverStep& WindowEstimator<Model>::step(long k, double t, const Eigen::VectorXd& y,
                                                 const Eigen::VectorXd& u) {
  const OutputWindow<Model>& window = state_->window;
  const Eigen::Index length = window.length();
  require_sample_sizes(name(), k, y, u, window.model().outputs(), window.model().inputs());
  step_.summary.reset();
  step_.failure.clear();
  step_.failure_message.clear();
  step_.measurement_missing = !y.allFinite();
  if (!clock_.place(name(), k, t, step_)) {  // off the grid: the window map assumes it
    step_.estimate = coast_;
    return step_;
  }
  const long moves = clock_.moves();
  clock_.commit();
  const long index = clock_.index();  // the model's index of this sample
  if (moves > 1) {  // a gap: the skipped samples are missing ones; coast over all but the last
    state_->window.clear();
    have_solution_ = false;
    for (long j = index - moves; j + 1 < index; ++j) {
      const State next = window.model().f(coast_, typename OutputWindow<Model>::Input(last_u_), j);
      accept_finite(next, coast_, step_, name(), k,
                    "the state coasted on the model from the last estimate");
    }
  }
  if (step_.measurement_missing) {
    state_->window.clear();  // consecutive samples only: refill after the gap
    have_solution_ = false;
  } else {
    state_->window.push(index, y, u);
  }
  step_.ready = window.full();
  bool solved = false;
  if (step_.ready) {
    // Guess for w = x̂[k−N+1]: the warm start after a usable solve, else the estimate kept
    // for that sample (coasted on the model; for N = 1 that is f(x̂[k−1]), not yet kept).
    State w = have_solution_ ? next_guess_ : coasted_guess(index, moves > 0);
    have_solution_ = false;
    Engine<N>& engine = (first_engine_ && !solved_once_) ? *first_engine_ : *engine_;
    // The first window's trace: recording on for this solve; the engine's own setting back
    // afterwards, even when the solve throws.
    struct RestoreTrace {
      RestoreTrace(Engine<N>* restored, bool setting) : engine(restored), before(setting) {}
      Engine<N>* engine;  // null: nothing to restore
      bool before;
      ~RestoreTrace() {
        if (engine) engine->set_record_trace(before);
      }
      RestoreTrace(const RestoreTrace&) = delete;
      RestoreTrace& operator=(const RestoreTrace&) = delete;
    };
    const bool trace = options_.trace_first_window && !solved_once_;
    const RestoreTrace restore{trace ? &engine : nullptr, engine.options().record_trace};
    if (trace) engine.set_record_trace(true);
    solved_once_ = true;
    step_.summary = solve_window(engine, w, k);
    if (step_.summary->usable() && consistent_with_noise(w, k)) {
      const State w1 = window.propagate(w, 1);  // x̂[k−N+2]
      // x̂[k] = f^{N−1}(w*): w* itself for a one-sample window.
      const State estimate = length == 1 ? w : window.propagate(w1, length - 2, 1);
      if (w1.allFinite() && estimate.allFinite()) {
        solved = have_solution_ = true;
        next_guess_ = options_.warm_start == WarmStart::kPrevious ? w : w1;
        coast_ = estimate;
      } else {
        std::ostringstream os;
        os << name() << ": the window's solution at sample k = " << k
           << " carried to x̂[k] by the model is not finite; the estimate coasts";
        mark_non_finite_estimate(step_, os.str());
      }
    }
  }
  // Otherwise x̂[k] comes from the model, f(x̂[k−1], u[k−1], k−1), from the guess at k = 0.
  if (!solved && moves > 0) {
    const State next =
        window.model().f(coast_, typename OutputWindow<Model>::Input(last_u_), index - 1);
    accept_finite(next, coast_, step_, name(), k,
                  "the state coasted on the model from the last estimate");
  }
  last_u_ = u;
  history_[slot(index)] = coast_;
  step_.estimate = coast_;
  return step_;
}

template <DiscreteModel Model>
bool WindowEstimator<Model>::consistent_with_noise(const State& w, long k) {
  if (!check_consistency_) return true;
  const OutputWindow<Model>& window = state_->window;
  const Eigen::Index p = window.model().outputs(), n = window.states();
  window.map_into(w, predicted_);
  root_->jacobian(w, window_jacobian_);
  // z = L⁻¹ (Y − H(w*)) and L⁻¹ ∂F/∂w, sample by sample.
  whitened_ = window.outputs() - predicted_;
  const auto factor = noise_factor_.matrixL();
  for (Eigen::Index j = 0; j < window.length(); ++j) {
    auto residual = whitened_.segment(j * p, p);
    factor.solveInPlace(residual);
    auto rows = window_jacobian_.middleRows(j * p, p);
    factor.solveInPlace(rows);
  }
  // 2V = ‖(I − P) z‖²: the entries of Qᵀ z beyond the first n, Q R the QR of L⁻¹ ∂F/∂w —
  // trusted only when the Gauss–Newton step it stands for, δ = R⁻¹ (Qᵀ z)_{1..n}, is small;
  // otherwise (∂H/∂w nearly singular, as at a flat local minimum, or w* far from the weighted
  // minimum) the plain ‖z‖².
  const double plain = whitened_.squaredNorm();
  projection_.compute(window_jacobian_);
  projection_.householderQ().adjoint().applyThisOnTheLeft(whitened_, householder_workspace_);
  const State step =
      projection_.matrixQR().topRows(n).template triangularView<Eigen::Upper>().solve(
          whitened_.head(n));
  const double reach = kLargestRefinement * (1.0 + w.template lpNorm<Eigen::Infinity>());
  const bool small_step = step.allFinite() && step.template lpNorm<Eigen::Infinity>() <= reach;
  const double statistic = small_step ? whitened_.tail(whitened_.size() - n).squaredNorm() : plain;
  if (statistic <= consistency_bound_) return true;
  std::ostringstream os;
  os << name() << ": the window's answer at sample k = " << k;
  if (std::isfinite(statistic)) {
    os << " is inconsistent with the declared noise R: 2V = " << statistic << " > "
       << consistency_bound_ << ", the " << options_.consistency_quantile << " quantile of chi2("
       << window.rows() - n
       << ") (N p - n degrees of freedom); a local minimum, or a model that does not fit the "
          "data: the estimate coasts";
  } else {
    os << " has a residual or window Jacobian that is not finite: it cannot be checked against "
          "the declared noise R, and the estimate coasts";
  }
  if (step_.failure.empty()) {
    step_.failure = "inconsistent_with_noise";
    step_.failure_message = os.str();
  }
  return false;
}

template <DiscreteModel Model>
auto WindowEstimator<Model>::coasted_guess(long k, bool moved) const -> State {
  const Eigen::Index length = state_->window.length();
  if (length > 1) return history_[slot(k + 1)];
  if (!moved) return initial_guess_;
  const State next =
      state_->window.model().f(coast_, typename OutputWindow<Model>::Input(last_u_), k - 1);
  return next.allFinite() ? next : coast_;
}

template <DiscreteModel Model>
Summary WindowEstimator<Model>::solve_window(Engine<N>& engine, State& w, long k) {
  if (!square_) {
    Summary s = engine.solve_least_squares(*root_, w);
    if (!s.answer_recorded) s.record_answer(w, engine.options().stop, /*minimised=*/true);
    return s;
  }
  const State guess = w;
  if (!gain_chosen_) {
    choose_gain(engine, guess, k);
    gain_chosen_ = true;
  }
  Summary s = solve_once(engine, w);
  if (s.status == Status::kSingularJacobian) {
    // A guess where ∂H/∂w is singular (an equilibrium, say) is a point the window cannot see
    // from: leave it by a small deterministic offset rather than stay stuck at it.
    if (!warned_singular_) {
      warned_singular_ = true;
      std::ostringstream os;
      os << name() << ": the guess w = [" << guess.transpose() << "] at k = " << k
         << " is a singular point of the window map (" << s.message
         << "): the state is not observable from the window there (an equilibrium?); solves "
            "from such a guess restart from a perturbed one";
      info_.warnings.push_back(os.str());
    }
    for (Eigen::Index i = 0; i < w.size(); ++i) {
      const double sign = i % 2 == 0 ? 1.0 : -1.0;
      w[i] = guess[i] + sign * kPerturbation * (1.0 + 0.1 * static_cast<double>(i)) *
                            std::max(1.0, std::abs(guess[i]));
    }
    if (active_gain_ == WindowGain::kNewton) gain_stale_ = true;
    const int evaluations = s.function_evaluations, jacobians = s.jacobian_evaluations;
    s = solve_once(engine, w);
    s.function_evaluations += evaluations;  // the step's cost is both solves'
    s.jacobian_evaluations += jacobians;
  }
  if (active_gain_ == WindowGain::kNewton &&
      (!s.usable() || (s.contraction_estimate && !(*s.contraction_estimate < 1.0)))) {
    gain_stale_ = true;
  }
  return s;
}

template <DiscreteModel Model>
Summary WindowEstimator<Model>::solve_once(Engine<N>& engine, State& w) {
  int gain_jacobians = 0;  // ∂H/∂w for Ψ: counted in the step's Summary
  if (active_gain_ == WindowGain::kNewton && gain_stale_) {
    ++gain_jacobians;
    if (refresh_newton_gain(w)) {
      gain_stale_ = false;
      gain_valid_ = true;
    } else if (!gain_valid_) {
      Summary s;
      s.engine = engine.name();
      s.status = Status::kSingularJacobian;
      s.jacobian_evaluations = gain_jacobians;
      s.message = "dH/dw is singular or not finite at the guess: no gain Psi = (dH/dw)^-1";
      s.record_answer(w, engine.options().stop);
      return s;
    }
  }
  const FixedPointProblem<N>& problem =
      active_gain_ == WindowGain::kIdentity ? *fixed_point_ : *gain_point_;
  Summary s = engine.solve(problem, w);
  if (!s.answer_recorded) s.record_answer(w, engine.options().stop);
  s.jacobian_evaluations += gain_jacobians;
  return s;
}

template <DiscreteModel Model>
void WindowEstimator<Model>::choose_gain(const Engine<N>& engine, const State& w, long k) {
  if (active_gain_ == WindowGain::kNewton) return;
  if (!engine.needs_contraction()) {
    if (active_gain_ == WindowGain::kAuto) active_gain_ = WindowGain::kIdentity;
    return;
  }
  const Eigen::Index n = w.size();
  Gain dh(n, n);
  const Gain& psi = state_->gain;  // I, or gain_scale·I (reset()); newton never reaches here
  double rho = std::nan("");
  if (window_jacobian(w, dh)) rho = spectral_radius(Gain(Gain::Identity(n, n) - psi * dh));
  if (rho < 1.0) {
    if (active_gain_ == WindowGain::kAuto) active_gain_ = WindowGain::kIdentity;
    return;
  }
  std::ostringstream os;
  os << name() << ": Psi = ";
  if (active_gain_ == WindowGain::kScalar) os << options_.gain_scale << " ";
  os << "I does not contract at the first window (spectral radius of dG = I - Psi dH/dw is " << rho
     << " at the guess, k = " << k << ")";
  if (active_gain_ == WindowGain::kAuto) {
    active_gain_ = WindowGain::kNewton;
    os << "; chose psi = newton (Psi = (dH/dw)^-1, the chord Newton map)";
  } else {
    os << "; engine '" << spec_ << "' needs a contraction: psi = auto or newton makes G contract";
  }
  info_.warnings.push_back(os.str());
}

template <DiscreteModel Model>
bool WindowEstimator<Model>::refresh_newton_gain(const State& w) {
  const Eigen::Index n = w.size();
  Gain dh(n, n);
  if (!window_jacobian(w, dh)) return false;
  const Eigen::PartialPivLU<Gain> lu(dh);
  const auto pivots = lu.matrixLU().diagonal().cwiseAbs();
  if (!(pivots.minCoeff() > kSingularPivot * dh.cwiseAbs().maxCoeff())) return false;
  const Gain inverse = lu.inverse();
  if (!inverse.allFinite()) return false;
  state_->gain = inverse;
  return true;
}

template <DiscreteModel Model>
bool WindowEstimator<Model>::window_jacobian(const State& w, Gain& dh) const {
  square_residual_->jacobian(w, dh);  // ∂(Y − H)/∂w
  dh = -dh;
  return dh.allFinite();
}

template <DiscreteModel Model>
void WindowEstimator<Model>::require_least_squares_engine() const {
  if (engine_->least_squares()) return;
  std::ostringstream os;
  os << "a window of N = " << state_->window.length() << " samples gives " << state_->window.rows()
     << " > " << state_->window.states() << " equations; engine '" << spec_
     << "' solves square systems only: use ceres or nlopt (or N = n/p)";
  throw InvalidInput(os.str());
}

}  // namespace nlobs
