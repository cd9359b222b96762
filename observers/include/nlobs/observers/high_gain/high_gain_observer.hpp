#pragma once
// High-gain observer in embedded observability coordinates ([HG-EMB23]).
//
// For x' = f(x), y = h(x) and z = q_N(x) = [h, L_f h, …, L_f^{N−1} h], the system reads as the
// integrator chain z_i' = z_{i+1}, z_N' = α(z). The observer runs that chain with output
// injection ([HG-EMB23]):
//   ẑ_i' = ẑ_{i+1} + (l_{N−i} / θ^i)(y − ẑ_1),   ẑ_N' = ᾱ(ẑ) + (l_0 / θ^N)(y − ẑ_1),
// s^N + l_{N−1}s^{N−1} + … + l_0 Hurwitz (roots p_j; the linear error dynamics then has the roots
// p_j / θ), ᾱ = s_{ρ²}(‖ẑ‖²_P / R²) α the smooth saturation (smooth_saturation.hpp). The state
// estimate is the projection x̂ = argmin_x ‖ẑ − q_N(x)‖ (any least-squares engine object,
// warm-started from the previous x̂ or from its prediction through the model), or an explicit
// inverse when the user has one. The projection can jump where local minima merge or split: jumps
// larger than a threshold are counted.
//
// α: an explicit α(z) (embedded_forms.hpp has [HG-EMB23]'s Duffing and oscillator), or — for models
// whose α is rational or unknown (Lorenz, Van der Pol) — L_f^N h evaluated along the model's
// prediction x̄ from the last projection (x̄' = f(x̄), reset to x̂ at each sample). That is an
// approximation: it equals z_N' exactly once x̂ = x, and is only as good as the projection before.
// Near the non-observable set the projection is ill-determined, so it is weighted by
// w = σ² / (σ² + ε²), σ = σ_min(∂q_N/∂x) at x̂ (ε = observability_floor): the observer falls back
// to the pure integrator chain there.
//
// Samples as in every sampled-data observer (sampled_data.hpp): y between samples is the cubic
// through the last four good samples, u held. Integration (interval_integrator.hpp): RK4 with
// `substeps` per sample, or SUNDIALS CVODE (BDF, dense, our Jacobian) for stiff gains; `auto` picks
// CVODE when h · max|p_j| / θ exceeds 0.2 (bench BM_HighGainIntegrator: RK4 is as accurate and
// ~200× cheaper up to 0.1, its error reaches 1e-2 at 0.33 and it diverges beyond 2.8;
// docs/observers.md).
#include <Eigen/Core>
#include <cmath>
#include <complex>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "nlobs/models/catalogue.hpp"
#include "nlobs/models/model.hpp"
#include "nlobs/observers/core/interval_integrator.hpp"
#include "nlobs/observers/core/model_derivatives.hpp"
#include "nlobs/observers/core/observer.hpp"
#include "nlobs/observers/core/option_checks.hpp"
#include "nlobs/observers/core/sampled_data.hpp"
#include "nlobs/observers/high_gain/high_gain_design.hpp"
#include "nlobs/observers/high_gain/observability_map.hpp"
#include "nlobs/observers/high_gain/smooth_saturation.hpp"
#include "nlobs/solvers/engine_registry.hpp"

namespace nlobs {

enum class HighGainIntegrator { kAuto, kRk4, kCvode };
enum class ProjectionStart { kPrevious, kPredicted };

inline std::string_view to_string(HighGainIntegrator i) {
  switch (i) {
    case HighGainIntegrator::kAuto:
      return "auto";
    case HighGainIntegrator::kRk4:
      return "rk4";
    case HighGainIntegrator::kCvode:
      return "cvode";
  }
  return "unknown";
}

// ẑ_N' = α(ẑ) with its gradient (needed by the implicit integrator only).
struct EmbeddedAlpha {
  std::function<double(const Eigen::VectorXd&)> value;
  std::function<void(const Eigen::VectorXd&, Eigen::VectorXd&)> gradient;
};

// x = q_N^{-1}(z), exact on the image of q_N.
using EmbeddedInverse = std::function<void(const Eigen::VectorXd& z, Eigen::VectorXd& x)>;

// α of a form with `template <class T> T alpha(const Eigen::Matrix<T, kDimension, 1>&)`; its
// gradient by ceres::Jet.
template <typename Form>
EmbeddedAlpha explicit_alpha(Form form = {}) {
  constexpr int N = Form::kDimension;
  EmbeddedAlpha a;
  a.value = [form](const Eigen::VectorXd& z) { return form.alpha(Eigen::Matrix<double, N, 1>(z)); };
  a.gradient = [form](const Eigen::VectorXd& z, Eigen::VectorXd& g) {
    using Jet = ceres::Jet<double, N>;
    Eigen::Matrix<Jet, N, 1> zj;
    for (int i = 0; i < N; ++i) zj[i] = Jet(z[i], i);
    g = form.alpha(zj).v;
  };
  return a;
}

template <typename Form>
EmbeddedInverse explicit_inverse(Form form = {}) {
  return [form](const Eigen::VectorXd& z, Eigen::VectorXd& x) {
    x = form.inverse(Eigen::Matrix<double, Form::kDimension, 1>(z));
  };
}

// What the observer is made of: q_N, α and (optionally) q_N's inverse. The design helpers
// (high_gain_design.hpp, embedded_forms.hpp, lie_observability_map.hpp) build them.
struct HighGainDesign {
  std::shared_ptr<const ObservabilityMap> map{};  // q_N (required)
  EmbeddedAlpha alpha{};      // empty: α = L_f^N h along the prediction (map->has_next())
  EmbeddedInverse inverse{};  // empty: x̂ by the projection engine
};

struct HighGainOptions {
  std::string name = "high_gain";    // in reports
  Eigen::VectorXd initial_estimate;  // x̂(0): n finite numbers (required)
  std::optional<Eigen::VectorXd> initial_embedded_estimate{};  // ẑ(0) (N numbers); unset: q_N(x̂(0))
  HighGainDesign design{};
  double sample_time = 0.0;
  double theta = 0.1;  // θ > 0: gains l_{N−i} / θ^i
  // Roots p_j of s^N + l_{N−1}s^{N−1} + … + l_0, real and < 0; empty: all at −1 (the paper).
  std::vector<double> poles{};
  // Or the coefficients [l_0, …, l_{N−1}] directly (complex roots); must be Hurwitz.
  Eigen::VectorXd coefficients{};
  std::optional<SmoothSaturation> saturation{};  // none: ᾱ = α
  HighGainIntegrator integrator = HighGainIntegrator::kAuto;
  int substeps = 1;                                               // RK4 steps per sample interval
  double absolute_tolerance = 1e-10, relative_tolerance = 1e-10;  // CVODE
  ProjectionStart start = ProjectionStart::kPrevious;
  double jump_threshold = 0.1;  // ‖x̂_k − x̄(t_k)‖∞ above this is a jump (x̄: prediction)
  double observability_floor = 1e-2;  // ε of the weight of α = L_f^N h (see above)
  double residual_scale = 0.1;        // ρ_r of the same weight's residual factor
  // Restart the projection from x̂(0) and 0 when ‖ẑ − q_N(x̂)‖ > this · (1 + ‖ẑ‖); 0: never.
  double restart_residual = 1e-2;
  // At most one restart per this many samples. 1 (default): the Duffing hard start needs them
  // at every sample while ẑ converges (with 100, x̂ wandered at residual ~1 in wrong minima);
  // under noise ẑ stays off the image and every sample restarts — raise it there (cost).
  int restart_every = 1;
  // Throws InvalidInput naming the field and its value for what the options alone can tell:
  // an empty name, x̂(0) or ẑ(0) not finite, no map, N < 2, no α from a map that cannot give
  // L_f^N h, θ, T, tolerances, thresholds out of range, an invalid saturation.
  void validate() const;
};

// The solver options of the default projection engine (Ceres): tight step and residual
// tolerances, 100 iterations — the projection's accuracy bounds x̂'s. Give an engine built
// from a spec the same (the CLI does): EngineRegistry<n>::global().create(spec, these).
SolverOptions high_gain_projection_options();

template <ContinuousModel Model>
class HighGainObserver final : public Observer {
 public:
  static constexpr int n = Model::kStates;
  static_assert(n != Eigen::Dynamic, "HighGainObserver needs a model with a compile-time size");
  static_assert(Model::kOutputs == 1, "the high-gain observer of [HG-EMB23] has one output");
  using State = ModelVector<double, n>;

  using Design = HighGainDesign;

  // x̂ = argmin ‖ẑ − q_N(x)‖ by `projection` (any least-squares engine, or a square one when
  // N = n); none given and no explicit inverse: Ceres with high_gain_projection_options().
  // Throws InvalidInput naming the field for invalid options (HighGainOptions::validate()),
  // sizes that do not fit the model, a time-varying model, an engine beside an inverse.
  HighGainObserver(Model model, HighGainOptions options,
                   std::unique_ptr<Engine<n>> projection = nullptr);
  HighGainObserver(const HighGainObserver&) = delete;
  HighGainObserver& operator=(const HighGainObserver&) = delete;

  // z = q_N(x), NaN where q_N is not finite (the model is autonomous: t does not enter).
  Eigen::VectorXd coordinates_at(const Eigen::VectorXd& x, double /*t*/) const override {
    Eigen::VectorXd z(N_);
    if (x.size() != n || !design_.map->value(x, z)) z.setConstant(std::nan(""));
    return z;
  }

  const HighGainOptions& options() const { return options_; }
  HighGainIntegrator integrator() const { return integrator_; }
  const Eigen::VectorXd& coefficients() const { return coefficients_; }  // l_0 … l_{N−1}
  const Eigen::VectorXd& gains() const { return gains_; }  // l_{N−i} / θ^i, i = 1…N
  const Eigen::VectorXd& zhat() const { return zhat_; }
  const State& xhat() const { return xhat_; }
  double projection_residual() const { return residual_; }
  long jumps() const { return jumps_; }

  void reset() override;

  const ObserverStep& step(long k, double t, const Eigen::VectorXd& y,
                           const Eigen::VectorXd& u) override;

 private:
  // The observer's right-hand side at t for the state s = (ẑ, x̄) with y(t) given: [HG-EMB23].
  // False (derivatives zero) when α or f is not finite there.
  bool derivatives(double t, const double* s, double y, double* ds);

  bool zero(double* ds) const {
    for (Eigen::Index i = 0; i < state_size(); ++i) ds[i] = 0.0;
    return false;
  }
  Eigen::Index state_size() const { return N_ + (predict_ ? n : 0); }

  void set_coefficients();

  void allocate();

  // [t0, t1]; false (state untouched) when the right-hand side turned non-finite.
  bool integrate(double t0, double t1);

  // ∂(ẑ', x̄')/∂(ẑ, x̄) for the implicit integrator.
  void jacobian(double t, const double* s, Eigen::Map<Eigen::MatrixXd>& j);

  // s_{ρ²}(ẑᵀPẑ/R²) and its gradient in ẑ (by ceres::Jet through the smooth step).
  void saturation_gradient(double& value, Eigen::VectorXd& gradient) const;

  // x̂ from ẑ at t: the explicit inverse, or the least-squares projection.
  void project(double t);

  State solve_projection(Vector<n> x);

  // ‖ẑ − q_N(x)‖ (infinite when not finite).
  double residual_at(const State& x);

  // w = σ² / (σ² + ε²), σ = σ_min(∂q_N/∂x) at x̂: 0 on the non-observable set.
  void update_weight();

  const ObserverStep& publish();

  Model model_;
  HighGainOptions options_;
  const Design& design_ = options_.design;
  ModelDerivatives<Model> derivatives_;
  Eigen::Index N_ = 0;
  bool lie_alpha_ = false, predict_ = false;  // predict_: x̄' = f(x̄) integrated beside ẑ
  HighGainIntegrator integrator_ = HighGainIntegrator::kRk4;
  Eigen::VectorXd coefficients_, gains_;
  double spectral_radius_ = 1.0;
  std::unique_ptr<Engine<n>> engine_;
  std::optional<RootProblem<n, Eigen::Dynamic>> problem_;
  State xhat0_ = State::Zero(), xhat_ = State::Zero(), xbar_ = State::Zero();
  Eigen::VectorXd zhat0_, zhat_, zs_, z_, zhat_projected_, grad_alpha_, grad_sat_;
  Eigen::MatrixXd dq_;
  mutable Eigen::VectorXd x_;
  Eigen::VectorXd xd_ = Eigen::VectorXd::Zero(n);  // x̄ for the map's (dynamic-size) interface
  typename Model::Input input_ = Model::Input::Zero();  // u_{k−1}, held over the interval
  SampledData<1, Model::kInputs> clock_{1, Model::kInputs, options_.sample_time};  // y: cubic
  bool started_once_ = false;
  double residual_ = 0.0, weight_ = 1.0;
  long jumps_ = 0, samples_since_restart_ = 0;
  std::string failure_;
  std::vector<double> state_;
  std::optional<IntervalIntegrator> interval_;
  ObserverStep step_;
};

template <ContinuousModel Model>
HighGainObserver<Model>::HighGainObserver(Model model, HighGainOptions options,
                                          std::unique_ptr<Engine<n>> projection)
    : model_(std::move(model)),
      options_(detail::validated(std::move(options))),
      derivatives_(model_),
      engine_(std::move(projection)) {
  const auto fail = [this](const std::string& what) {
    throw InvalidInput(options_.name + ": " + what);
  };
  const ObservabilityMap& map = *design_.map;
  N_ = map.dimension();
  if (map.states() != n) {
    fail("the map's state dimension " + std::to_string(map.states()) + " is not the model's " +
         std::to_string(n));
  }
  if (N_ < n) {
    fail("N = " + std::to_string(N_) + " is smaller than the state dimension n = " +
         std::to_string(n) + ": q_N cannot be injective");
  }
  if (vector_field_depends_on_time(model_)) {
    fail("the model's vector field depends on t: this observer is for autonomous x' = f(x)");
  }
  set_coefficients();
  lie_alpha_ = !design_.alpha.value;
  predict_ = true;  // x̄ serves α (lie), the warm start (predicted) and the jump test
  detail::require_size("HighGainOptions", "initial_estimate", options_.initial_estimate, n);
  xhat0_ = options_.initial_estimate;
  zhat0_.resize(N_);
  if (options_.initial_embedded_estimate) {
    detail::require_size("HighGainOptions", "initial_embedded_estimate",
                         *options_.initial_embedded_estimate, N_);
    zhat0_ = *options_.initial_embedded_estimate;
  } else if (!map.value(xhat0_, zhat0_)) {
    fail("q_N(x̂(0)) is not finite");
  }
  if (design_.inverse && engine_) {
    fail("both an explicit inverse and a projection engine given: pass one");
  }
  if (!design_.inverse) {
    if (!engine_)
      engine_ = EngineRegistry<n>::global().create("ceres", high_gain_projection_options());
    problem_.emplace(RootProblem<n, Eigen::Dynamic>::with_jacobian(
        [this](const Vector<n>& x, Eigen::VectorXd& r) {
          x_ = x;
          if (!design_.map->value(x_, z_)) z_.setConstant(std::numeric_limits<double>::quiet_NaN());
          r = z_ - zhat_projected_;
        },
        [this](const Vector<n>& x, Matrix<Eigen::Dynamic, n>& jac) {
          x_ = x;
          if (design_.map->jacobian(x_, dq_)) {
            jac = dq_;
          } else {  // never the previous point's Jacobian
            jac.setConstant(std::numeric_limits<double>::quiet_NaN());
          }
        },
        n, N_));
    if (!engine_->least_squares() && N_ != n) {
      fail("projection engine '" + engine_->label() +
           "' solves square systems only (N = n); use ceres or nlopt");
    }
  }
  integrator_ = options_.integrator;
  if (integrator_ == HighGainIntegrator::kAuto) {
    // Largest |root| of the scaled error dynamics times the step (see the header comment).
    const double h = options_.sample_time / options_.substeps;
    integrator_ = h * spectral_radius_ / options_.theta > 0.2 ? HighGainIntegrator::kCvode
                                                              : HighGainIntegrator::kRk4;
  }
  if (integrator_ == HighGainIntegrator::kCvode && !ModelDerivatives<Model>::kAutoDiff &&
      predict_) {
    info_.warnings.push_back(options_.name +
                             ": ∂f for the implicit stepper by central differences");
  }
  info_.name = options_.name;
  info_.engine = design_.inverse ? "explicit inverse" : engine_->label();
  auto& signals = info_.signals;
  for (Eigen::Index i = 0; i < N_; ++i) {
    signals.push_back({"zhat" + std::to_string(i + 1), SignalKind::kEmbeddedEstimate});
  }
  signals.push_back({"projection_residual", SignalKind::kProjectionResidual});
  signals.push_back({"jumps", SignalKind::kJumpCount});
  signals.push_back({"alpha_weight"});
  allocate();
  reset();
}

template <ContinuousModel Model>
void HighGainObserver<Model>::reset() {
  zhat_ = zhat0_;
  xhat_ = xhat0_;
  clock_.reset();
  jumps_ = 0;
  residual_ = 0.0;
  weight_ = 1.0;
  started_once_ = false;
  samples_since_restart_ = 0;
  xbar_ = xhat0_;
}

template <ContinuousModel Model>
const ObserverStep& HighGainObserver<Model>::step(long k, double t, const Eigen::VectorXd& y,
                                                  const Eigen::VectorXd& u) {
  step_.ready = true;
  switch (clock_.receive(options_.name, k, t, y, u, step_)) {
    case SampledData<1, Model::kInputs>::kHold:
      return publish();
    case SampledData<1, Model::kInputs>::kStart:
      break;
    case SampledData<1, Model::kInputs>::kIntegrate:
      input_ = clock_.held_input();
      if (!integrate(clock_.last_time(), clock_.time())) {
        clock_.reject(step_, failure_);  // the last good state; the next sample goes on from it
        return publish();
      }
      break;
  }
  clock_.accept();
  project(clock_.time());
  return publish();
}

template <ContinuousModel Model>
bool HighGainObserver<Model>::derivatives(double t, const double* s, double y, double* ds) {
  zs_ = Eigen::Map<const Eigen::VectorXd>(s, N_);
  const double innovation = y - s[0];
  double alpha = 0.0;
  if (predict_) {
    xbar_ = Eigen::Map<const State>(s + N_);
    Eigen::Map<State>(ds + N_) = model_.vector_field(xbar_, input_, t);
  }
  if (lie_alpha_) {
    xd_ = xbar_;
    if (weight_ > 0.0 && !design_.map->next(xd_, alpha, nullptr)) return zero(ds);
    alpha *= weight_;
  } else {
    alpha = design_.alpha.value(zs_);
  }
  if (options_.saturation) alpha *= options_.saturation->factor(zs_);
  for (Eigen::Index i = 0; i + 1 < N_; ++i) ds[i] = s[i + 1] + gains_[i] * innovation;
  ds[N_ - 1] = alpha + gains_[N_ - 1] * innovation;
  for (Eigen::Index i = 0; i < N_; ++i) {
    if (!std::isfinite(ds[i])) return zero(ds);
  }
  for (Eigen::Index i = N_; i < state_size(); ++i) {
    if (std::isfinite(ds[i])) continue;
    if (lie_alpha_) return zero(ds);
    // With an explicit α, x̄ only warm-starts the projection: a prediction that blows up (x̂
    // far off, f superlinear) is frozen instead of failing the observer.
    for (Eigen::Index j = N_; j < state_size(); ++j) ds[j] = 0.0;
    break;
  }
  return true;
}

template <ContinuousModel Model>
void HighGainObserver<Model>::set_coefficients() {
  if (options_.coefficients.size() && !options_.poles.empty()) {
    throw InvalidInput(options_.name + ": give HighGainOptions::poles or coefficients, not both");
  }
  if (options_.coefficients.size()) {
    if (options_.coefficients.size() != N_ || !options_.coefficients.allFinite()) {
      detail::invalid_option("HighGainOptions", "coefficients",
                             "be N = " + std::to_string(N_) + " finite numbers [l_0, …, l_{N−1}]",
                             std::to_string(options_.coefficients.size()) +
                                 (options_.coefficients.allFinite() ? "" : ", not all finite"));
    }
    coefficients_ = options_.coefficients;
    const Eigen::VectorXcd roots = polynomial_roots(coefficients_);
    for (const auto& r : roots) {
      if (!(r.real() < 0.0)) {
        std::ostringstream os;
        os << "the root " << r.real() << (r.imag() >= 0 ? " + " : " - ") << std::abs(r.imag())
           << "i: not Hurwitz";
        detail::invalid_option("HighGainOptions", "coefficients",
                               "make s^N + l_{N−1}s^{N−1} + … + l_0 Hurwitz", os.str());
      }
    }
    spectral_radius_ = roots.cwiseAbs().maxCoeff();
  } else {
    std::vector<double> poles = options_.poles;
    if (poles.empty()) poles.assign(static_cast<size_t>(N_), -1.0);
    if (static_cast<Eigen::Index>(poles.size()) != N_) {
      detail::invalid_option("HighGainOptions", "poles",
                             "list N = " + std::to_string(N_) + " roots (or none: all −1)",
                             std::to_string(poles.size()));
    }
    coefficients_ = hurwitz_coefficients(poles);  // refuses a root that is not real and < 0
    spectral_radius_ = 0.0;
    for (double p : poles) spectral_radius_ = std::max(spectral_radius_, std::abs(p));
  }
  gains_.resize(N_);
  for (Eigen::Index i = 1; i <= N_; ++i) {
    gains_[i - 1] = coefficients_[N_ - i] / std::pow(options_.theta, static_cast<double>(i));
  }
  if (!gains_.allFinite()) {
    detail::invalid_option(
        "HighGainOptions", "theta",
        "keep the gains l_{N−i}/θ^i finite (they overflow for N = " + std::to_string(N_) + ")",
        detail::option_value(options_.theta));
  }
}

template <ContinuousModel Model>
void HighGainObserver<Model>::allocate() {
  zhat_.resize(N_);
  zs_.resize(N_);
  z_.resize(N_);
  zhat_projected_.resize(N_);
  dq_.resize(N_, n);
  x_.resize(n);
  state_.assign(static_cast<size_t>(state_size()), 0.0);
  step_.estimate.resize(n);
  step_.signals.resize(static_cast<Eigen::Index>(info_.signals.size()));
  IntervalIntegratorOptions o;
  o.scheme =
      integrator_ == HighGainIntegrator::kCvode ? IntervalScheme::kCvode : IntervalScheme::kRk4;
  o.sample_time = options_.sample_time;
  o.substeps = options_.substeps;
  o.absolute_tolerance = options_.absolute_tolerance;
  o.relative_tolerance = options_.relative_tolerance;
  const Eigen::Index size = state_size();
  interval_.emplace(
      static_cast<int>(size),
      [this](double t, const double* s, double* ds) {
        return derivatives(t, s, clock_.output_at(t)[0], ds);
      },
      o,
      [this, size](double t, const double* s, double* j) {
        Eigen::Map<Eigen::MatrixXd> jac(j, size, size);
        jacobian(t, s, jac);
      });
}

template <ContinuousModel Model>
bool HighGainObserver<Model>::integrate(double t0, double t1) {
  failure_.clear();
  for (Eigen::Index i = 0; i < N_; ++i) state_[static_cast<size_t>(i)] = zhat_[i];
  if (predict_) {
    for (int i = 0; i < n; ++i) state_[static_cast<size_t>(N_ + i)] = xhat_[i];
  }
  bool finite = interval_->integrate(t0, t1, state_, &failure_);
  if (!finite && !failure_.empty()) failure_ = options_.name + ": " + failure_;  // CVODE's reason
  for (Eigen::Index i = 0; i < state_size(); ++i) {
    if (std::isfinite(state_[static_cast<size_t>(i)])) continue;
    if (i < N_ || lie_alpha_) {
      finite = false;
    } else {  // a blown-up prediction (explicit α): predict nothing this step
      for (int j = 0; j < n; ++j) state_[static_cast<size_t>(N_ + j)] = xhat_[j];
    }
  }
  if (!finite) {
    if (failure_.empty()) {
      std::ostringstream os;
      os << options_.name << ": the observer's right-hand side is not finite between t = " << t0
         << " and " << t1 << " (ẑ = " << zhat_.transpose() << ")";
      failure_ = os.str();
    }
    return false;
  }
  for (Eigen::Index i = 0; i < N_; ++i) zhat_[i] = state_[static_cast<size_t>(i)];
  if (predict_) {
    for (int i = 0; i < n; ++i) xbar_[i] = state_[static_cast<size_t>(N_ + i)];
  } else {
    xbar_ = xhat_;
  }
  return true;
}

template <ContinuousModel Model>
void HighGainObserver<Model>::jacobian(double t, const double* s, Eigen::Map<Eigen::MatrixXd>& j) {
  j.setZero();
  for (Eigen::Index i = 0; i < N_; ++i) {
    if (i + 1 < N_) j(i, i + 1) = 1.0;
    j(i, 0) -= gains_[i];
  }
  zs_ = Eigen::Map<const Eigen::VectorXd>(s, N_);
  double sat = 1.0;
  Eigen::VectorXd& grad_sat = grad_sat_;
  grad_sat.setZero(N_);
  if (options_.saturation) saturation_gradient(sat, grad_sat);
  if (predict_) {
    xbar_ = Eigen::Map<const State>(s + N_);
    typename ModelDerivatives<Model>::Jacobian df;
    derivatives_.jacobian(xbar_, input_, t, df);
    for (int r = 0; r < n; ++r) {
      for (int c = 0; c < n; ++c) j(N_ + r, N_ + c) = df(r, c);
    }
  }
  if (lie_alpha_) {
    xd_ = xbar_;
    double alpha = 0.0;
    if (weight_ > 0.0 && design_.map->next(xd_, alpha, &grad_alpha_)) {
      for (int c = 0; c < n; ++c) j(N_ - 1, N_ + c) = sat * weight_ * grad_alpha_[c];
      for (Eigen::Index c = 0; c < N_; ++c) j(N_ - 1, c) += weight_ * alpha * grad_sat[c];
    }
  } else {
    const double alpha = design_.alpha.value(zs_);
    if (design_.alpha.gradient) design_.alpha.gradient(zs_, grad_alpha_);
    for (Eigen::Index c = 0; c < N_; ++c) {
      j(N_ - 1, c) += sat * (design_.alpha.gradient ? grad_alpha_[c] : 0.0) + alpha * grad_sat[c];
    }
  }
}

template <ContinuousModel Model>
void HighGainObserver<Model>::saturation_gradient(double& value, Eigen::VectorXd& gradient) const {
  const SmoothSaturation& sat = *options_.saturation;
  const double q = zs_.dot(sat.P * zs_) / (sat.R * sat.R);
  using Jet = ceres::Jet<double, 1>;
  const Jet s = smooth_step(Jet(q, 0), sat.rho * sat.rho);
  value = s.a;
  gradient = (s.v[0] * 2.0 / (sat.R * sat.R)) * (sat.P * zs_);
}

template <ContinuousModel Model>
void HighGainObserver<Model>::project(double t) {
  const State previous = xhat_, predicted = xbar_;
  State candidate;
  if (design_.inverse) {
    design_.inverse(zhat_, x_);
    candidate = x_;
  } else {
    zhat_projected_ = zhat_;
    candidate = solve_projection(
        options_.start == ProjectionStart::kPredicted && xbar_.allFinite() ? xbar_ : previous);
    // A poor local minimum: restart from x̂(0) and the origin, keep the best of all.
    ++samples_since_restart_;
    if (options_.restart_residual > 0.0 && samples_since_restart_ >= options_.restart_every &&
        !(residual_at(candidate) <= options_.restart_residual * (1.0 + zhat_.norm()))) {
      samples_since_restart_ = 0;
      for (const State& start : {xhat0_, State(State::Zero())}) {
        const State other = solve_projection(start);
        if (residual_at(other) < residual_at(candidate)) candidate = other;
      }
    }
  }
  x_ = candidate;
  const bool ok = candidate.allFinite() && design_.map->value(x_, z_);
  if (!ok) {
    step_.failure = "projection";
    std::ostringstream os;
    os << options_.name << ": the projection of ẑ = [" << zhat_.transpose() << "] at t = " << t
       << " failed (no finite x̂); x̂ kept";
    step_.failure_message = os.str();
    residual_ = std::numeric_limits<double>::quiet_NaN();  // no x̂ belongs to this ẑ
    return;
  }
  residual_ = (z_ - zhat_).norm();
  xhat_ = candidate;
  // A jump: x̂ moved away from where the model carried the previous x̂.
  if ((xhat_ - predicted).template lpNorm<Eigen::Infinity>() > options_.jump_threshold &&
      started_once_) {
    ++jumps_;
  }
  started_once_ = true;
  if (lie_alpha_) update_weight();
}

// The projection is a best fit, min ‖q_N(x) − ẑ‖, not a root: ẑ is off the image of q_N between
// samples, so Summary::usable() (a root's residual) does not apply. A few warm-started
// iterations improve x̂ whatever the status; project() keeps x̂ when the answer is not finite
// and publishes the fit's residual.
template <ContinuousModel Model>
auto HighGainObserver<Model>::solve_projection(Vector<n> x) -> State {
  try {
    const Summary s = engine_->solve_least_squares(*problem_, x);
    if (s.status == Status::kInvalidInput) throw InvalidInput(s.message);
  } catch (const InvalidInput&) {
    x.setConstant(std::nan(""));
  }
  return x;
}

template <ContinuousModel Model>
double HighGainObserver<Model>::residual_at(const State& x) {
  x_ = x;
  if (!x.allFinite() || !design_.map->value(x_, z_)) return HUGE_VAL;
  return (z_ - zhat_).norm();
}

template <ContinuousModel Model>
void HighGainObserver<Model>::update_weight() {
  x_ = xhat_;
  if (!design_.map->jacobian(x_, dq_)) {
    weight_ = 0.0;
    return;
  }
  const double c = smallest_singular_value(dq_);
  const double eps = options_.observability_floor;
  weight_ = eps > 0.0 ? c * c / (c * c + eps * eps) : 1.0;
  // ẑ off the image of q_N (residual large against ‖ẑ‖): x̂ says little about ẑ's α.
  const double r = residual_ / (options_.residual_scale * (1.0 + zhat_.norm()));
  weight_ /= 1.0 + r * r;
}

template <ContinuousModel Model>
const ObserverStep& HighGainObserver<Model>::publish() {
  step_.estimate = xhat_;
  step_.signals.head(N_) = zhat_;
  step_.signals[N_] = residual_;
  step_.signals[N_ + 1] = static_cast<double>(jumps_);
  step_.signals[N_ + 2] = lie_alpha_ ? weight_ : 1.0;
  return step_;
}

// Compiled once in the observers library for the catalogue's models (src/instances/).
#define NLOBS_EXTERN_HIGH_GAIN_OBSERVER(M, lowest) extern template class HighGainObserver<M>;
NLOBS_FOR_EACH_AUTONOMOUS_SINGLE_OUTPUT_CATALOGUE_MODEL(NLOBS_EXTERN_HIGH_GAIN_OBSERVER)
#undef NLOBS_EXTERN_HIGH_GAIN_OBSERVER

}  // namespace nlobs
