#pragma once
// Mean-value-theorem observer ([BMH]) for x' = F(x, u, t), y = C x, C = [I_m 0]:
//
//     x̂' = F(x̂, u) + Ḡ e1,             e1 = [y − C x̂ ; ê_{m+1..n}]
//     ê' = (D − Ḡ) ê  [+ K ν]            ν  = (y − C x̂) − C ê       (output-injection variant)
//
// D is the MVT Jacobian at the solved β (mvt_beta.hpp), Ḡ = η diag(α), α_k = Σ_j |D_kj| + Σ_i
// |D_ik| (row plus column sums), η ≥ 1.
//
// What the published structure does: with w = x̂ + ê, the two equations add up to
//     w' = F(w) + Ḡ [C (x − w) ; 0],
// an output-injection observer whose unmeasured components get no correction at all, and
// ê' = F(w) − F(x̂) − Ḡ ê decays on its own. So ê tracks e = x − x̂ exactly when ê(0) = x(0) −
// x̂(0) (w is then x), but from any other ê(0) the unmeasured error x_b − w_b is left to the
// open-loop dynamics (case 2 of the paper: x3's error stays at 0.06–0.18).
//
// The correction (ours, variant kOutputInjection, the default): feed the measured innovation
// ν = C(x − w) into the unmeasured rows of ê with K = [0 ; K_b],
//     K_b = J_ba + γ J_abᵀ Ḡ_a,     J = ∂F/∂x at w,  a = measured, b = unmeasured rows/columns.
// With ε = x − w and the error system linearised at w (A ≈ J),
//     ε_a' = (J_aa − Ḡ_a) ε_a + J_ab ε_b,    ε_b' = J_bb ε_b − γ J_abᵀ Ḡ_a ε_a,
// and V = ½|ε_b|² + (γ/2) ε_aᵀ Ḡ_a ε_a the cross terms cancel:
//     V' = ε_bᵀ J_bb ε_b − γ ε_aᵀ Ḡ_a (Ḡ_a − J_aa) ε_a + (γ/2) ε_aᵀ Ḡ_a' ε_a.
// With J_bb ≤ 0 (zero in both paper examples), Ḡ_a dominating J_aa (what α's row and column
// sums are for) and Ḡ_a varying slowly against its size, V decreases; ε_b → 0 follows when J_ab
// is persistently exciting (ε_b shows in ε_a'). In the quasi-steady state ε_a ≈ Ḡ_a⁻¹ J_ab ε_b,
// so ε_b' ≈ (J_bb − γ J_abᵀ J_ab) ε_b: the Ḡ_a weighting makes the rate γ|J_ab|², independent of
// the high gain (without it the rate is γ J_abᵀ Ḡ_a⁻¹ J_ab, 1/71 per unit γ on the robot). This
// is an argument, not a proof: the Ḡ_a' term and the gap between J and the exact MVT matrix
// are not bounded here. When ν ≡ 0 (case 1) the correction is identically zero. Measured in
// docs/observers.md.
//
// On samples (sampled_data.hpp, the skeleton the MVT, high-gain and PI-bank observers share):
// the interval [t_{k−1}, t_k] is integrated when y_k arrives (interval_integrator.hpp: RK4 with
// `substeps` steps per sample, or adaptive Dormand–Prince); y between samples is the cubic
// through the last four good samples, u is held (the plant's sampled input). β is solved inside
// the right-hand side at every evaluation, warm-started from the last β. The β and Ḡ published
// with x̂_k are those of the step's last right-hand side (RK4's last stage, at t_k).
#include <array>
#include <cmath>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "nlobs/models/catalogue.hpp"
#include "nlobs/observers/core/interval_integrator.hpp"
#include "nlobs/observers/core/observer.hpp"
#include "nlobs/observers/core/option_checks.hpp"
#include "nlobs/observers/core/sampled_data.hpp"
#include "nlobs/observers/mvt/mvt_beta.hpp"
#include "nlobs/observers/mvt/mvt_options.hpp"

namespace nlobs {

template <ContinuousModel Model>
class MvtObserver final : public Observer {
 public:
  static constexpr int N = Model::kStates, P = Model::kOutputs, M = Model::kInputs;
  static_assert(N != Eigen::Dynamic && P != Eigen::Dynamic && M != Eigen::Dynamic,
                "MvtObserver needs a model with compile-time sizes");
  static_assert(P <= N, "more outputs than states");
  using State = ModelVector<double, N>;
  using Output = ModelVector<double, P>;
  using Input = ModelVector<double, M>;
  using Jacobian = Eigen::Matrix<double, N, N>;

  // Throws InvalidInput naming the field for invalid options (MvtOptions::validate()), starts
  // of the wrong size, and when the model's output is not y = [I_m 0] x.
  MvtObserver(Model model, MvtOptions options);
  MvtObserver(const MvtObserver&) = delete;
  MvtObserver& operator=(const MvtObserver&) = delete;

  const MvtOptions& options() const { return options_; }

  void reset() override;

  // Why the last failed derivatives() call failed (empty if none since the last step()).
  const std::string& last_failure() const { return failure_; }
  const State& xhat() const { return xhat_; }
  const State& ehat() const { return ehat_; }
  const State& beta() const { return beta_; }
  const State& gains() const { return gains_; }  // Ḡ's diagonal at the last evaluation
  const Jacobian& mvt_jacobian() const { return d_; }
  MvtBetaSolver<Model>& beta_solver() { return *beta_solver_; }

  // The right-hand side ([BMH]) at t for the state (x̂, ê), with y and u given: solves β
  // (warm-started from the last β; β, Ḡ and D are updated) and returns false, with zero
  // derivatives, when y, u, F or ∂F is not finite — the first such reason since the last
  // step() is last_failure(). For continuous-time use without samples (an ODE solver of the
  // caller's choice).
  bool derivatives(double t, const State& xhat, const State& ehat, const Output& y, const Input& u,
                   State& dxhat, State& dehat);

  const ObserverStep& step(long k, double t, const Eigen::VectorXd& y,
                           const Eigen::VectorXd& u) override;

 private:
  // y = C x with C = [I_m 0]: h(x) must equal the first m states at a few distinct points.
  void check_output_map() const;

  // [t0, t1] (interval_integrator.hpp); false (state untouched) when F turned non-finite.
  bool integrate(double t0, double t1);
  IntervalIntegrator make_integrator();

  const ObserverStep& publish();

  Model model_;  // before beta_solver_, which points to it
  MvtOptions options_;
  State xhat0_ = State::Zero(), ehat0_ = State::Zero();
  std::unique_ptr<MvtBetaSolver<Model>> beta_solver_;
  State xhat_ = State::Zero(), ehat_ = State::Zero(), beta_ = State::Zero(), gains_ = State::Zero();
  Jacobian d_ = Jacobian::Zero(), j_w_ = Jacobian::Zero();
  SampledData<P, M> clock_{P, M, options_.sample_time};  // y between samples: the cubic
  double max_residual_ = 0.0;
  std::string failure_;
  std::vector<double> state_ = std::vector<double>(2 * N);  // (x̂, ê) for the integrator
  IntervalIntegrator integrator_ = make_integrator();
  ObserverStep step_;
};

template <ContinuousModel Model>
MvtObserver<Model>::MvtObserver(Model model, MvtOptions options)
    : model_(std::move(model)), options_(detail::validated(std::move(options))) {
  detail::require_size("MvtOptions", "initial_estimate", options_.initial_estimate, N);
  xhat0_ = options_.initial_estimate;
  if (options_.initial_error_estimate.size() != 0) {
    detail::require_size("MvtOptions", "initial_error_estimate", options_.initial_error_estimate,
                         N);
    ehat0_ = options_.initial_error_estimate;
  }
  check_output_map();
  beta_solver_ = std::make_unique<MvtBetaSolver<Model>>(model_, options_.beta);
  info_.name = options_.name;
  info_.engine = std::string(to_string(options_.beta.method));
  if constexpr (!ModelDerivatives<Model>::kAutoDiff) {
    info_.warnings.push_back(options_.name +
                             ": the model's vector field does not accept ceres::Jet; ∂F by "
                             "central differences (β and D are then accurate to ~1e-7 only)");
  }
  auto& signals = info_.signals;
  signals.push_back({"residual", SignalKind::kSolveResidual});  // ‖X(β)‖ over the step
  for (int i = 0; i < N; ++i) signals.push_back({"beta" + std::to_string(i + 1)});
  for (int i = 0; i < N; ++i) signals.push_back({"ehat" + std::to_string(i + 1)});
  for (int i = 0; i < N; ++i) signals.push_back({"gain" + std::to_string(i + 1)});
  step_.estimate.resize(N);
  step_.signals.resize(static_cast<Eigen::Index>(signals.size()));
  reset();
}

template <ContinuousModel Model>
void MvtObserver<Model>::reset() {
  xhat_ = xhat0_;
  ehat_ = ehat0_;
  beta_.setConstant(0.5);
  gains_.setZero();
  clock_.reset();
  max_residual_ = 0.0;
}

template <ContinuousModel Model>
bool MvtObserver<Model>::derivatives(double t, const State& xhat, const State& ehat,
                                     const Output& y, const Input& u, State& dxhat, State& dehat) {
  const bool data_ok = y.allFinite() && u.allFinite();
  if (!data_ok || !beta_solver_->set_pair(xhat, ehat, u, t)) {
    dxhat.setZero();
    dehat.setZero();
    if (failure_.empty()) {
      std::ostringstream os;
      if (data_ok) {
        os << options_.name << ": F is not finite at t = " << t << " (x̂ = " << xhat.transpose()
           << ", x̂ + ê = " << (xhat + ehat).transpose() << ")";
      } else {
        os << options_.name << ": y or u is not finite at t = " << t;
      }
      failure_ = os.str();
    }
    return false;
  }
  const MvtBetaResult r = beta_solver_->solve(beta_);
  // NaN-propagating maximum: an unsolvable β problem must show in the report.
  if (!(r.residual_norm <= max_residual_)) max_residual_ = r.residual_norm;
  beta_solver_->mvt_jacobian(beta_, d_);
  if (!d_.allFinite()) {
    dxhat.setZero();
    dehat.setZero();
    if (failure_.empty()) {
      std::ostringstream os;
      os << options_.name << ": ∂F is not finite between x̂ and x̂ + ê at t = " << t
         << " (x̂ = " << xhat.transpose() << ", ê = " << ehat.transpose() << ")";
      failure_ = os.str();
    }
    return false;
  }
  const Jacobian abs = d_.cwiseAbs();
  gains_ = options_.eta * (abs.rowwise().sum() + abs.colwise().sum().transpose());  // η α
  const Output innovation = y - xhat.template head<P>();                            // y − C x̂
  State e1 = ehat;
  e1.template head<P>() = innovation;
  dxhat = beta_solver_->f_xhat() + gains_.cwiseProduct(e1);
  dehat = d_ * ehat - gains_.cwiseProduct(ehat);
  if (options_.variant == MvtVariant::kOutputInjection && N > P) {
    const Output nu = innovation - ehat.template head<P>();  // C (x − (x̂ + ê))
    beta_solver_->derivatives().jacobian(State(xhat + ehat), u, t, j_w_);
    // K_b ν = J_ba ν + γ J_abᵀ Ḡ_a ν
    dehat.tail(N - P).noalias() +=
        j_w_.bottomLeftCorner(N - P, P) * nu + options_.injection_gain *
                                                   j_w_.topRightCorner(P, N - P).transpose() *
                                                   gains_.template head<P>().cwiseProduct(nu);
  }
  return true;
}

template <ContinuousModel Model>
const ObserverStep& MvtObserver<Model>::step(long k, double t, const Eigen::VectorXd& y,
                                             const Eigen::VectorXd& u) {
  step_.ready = true;
  max_residual_ = 0.0;
  switch (clock_.receive(options_.name, k, t, y, u, step_)) {
    case SampledData<P, M>::kHold:
      return publish();
    case SampledData<P, M>::kStart: {
      // The first sample: the state is the initial condition; evaluate once to report β.
      failure_.clear();
      State dx, de;
      if (!derivatives(clock_.time(), xhat_, ehat_, Output(y), Input(u), dx, de)) {
        step_.failure = "non_finite";
        step_.failure_message = failure_;
      }
      break;
    }
    case SampledData<P, M>::kIntegrate:
      if (!integrate(clock_.last_time(), clock_.time())) {
        clock_.reject(step_, failure_);  // the last good state; the next sample goes on from it
        return publish();
      }
      break;
  }
  clock_.accept();
  return publish();
}

template <ContinuousModel Model>
void MvtObserver<Model>::check_output_map() const {
  std::array<State, 3> points = {xhat0_, State(xhat0_ + ehat0_), State::LinSpaced(N, 1.0, 2.0)};
  for (const State& x : points) {
    const Output y = model_.h(x);
    const double scale = 1.0 + x.template lpNorm<Eigen::Infinity>();
    if (!((y - x.template head<P>()).template lpNorm<Eigen::Infinity>() <= 1e-12 * scale)) {
      std::ostringstream os;
      os << "MvtObserver: the output must be y = C x with C = [I_m 0] (the first " << P
         << " states measured); at x = [" << x.transpose() << "] the model gives y = ["
         << y.transpose() << "]";
      throw InvalidInput(os.str());
    }
  }
}

template <ContinuousModel Model>
IntervalIntegrator MvtObserver<Model>::make_integrator() {
  IntervalIntegratorOptions o;
  o.scheme = options_.integrator == MvtIntegrator::kDopri5 ? IntervalScheme::kDopri5
                                                           : IntervalScheme::kRk4;
  o.sample_time = options_.sample_time;
  o.substeps = options_.substeps;
  o.absolute_tolerance = options_.absolute_tolerance;
  o.relative_tolerance = options_.relative_tolerance;
  return IntervalIntegrator(
      2 * N,
      [this](double t, const double* z, double* dz) {
        State dx, de;
        const bool finite =
            derivatives(t, Eigen::Map<const State>(z), Eigen::Map<const State>(z + N),
                        clock_.output_at(t), clock_.held_input(), dx, de);
        Eigen::Map<State>{dz} = dx;
        Eigen::Map<State>(dz + N) = de;
        return finite;
      },
      o);
}

template <ContinuousModel Model>
bool MvtObserver<Model>::integrate(double t0, double t1) {
  failure_.clear();
  const State beta0 = beta_, gains0 = gains_;
  const Jacobian d0 = d_;
  Eigen::Map<State>(state_.data()) = xhat_;
  Eigen::Map<State>(state_.data() + N) = ehat_;
  const bool finite = integrator_.integrate(t0, t1, state_);
  const State x = Eigen::Map<const State>(state_.data()),
              e = Eigen::Map<const State>(state_.data() + N);
  if (!finite || !x.allFinite() || !e.allFinite()) {
    if (failure_.empty()) failure_ = options_.name + ": the state is not finite after the step";
    beta_ = beta0, gains_ = gains0, d_ = d0;  // all that is published stays the last good step's
    return false;
  }
  xhat_ = x;
  ehat_ = e;
  return true;
}

template <ContinuousModel Model>
const ObserverStep& MvtObserver<Model>::publish() {
  step_.estimate = xhat_;
  step_.signals[0] = max_residual_;
  step_.signals.segment(1, N) = beta_;
  step_.signals.segment(1 + N, N) = ehat_;
  step_.signals.segment(1 + 2 * N, N) = gains_;
  return step_;
}

// Compiled once in the observers library for the catalogue's models (src/instances/).
#define NLOBS_EXTERN_MVT_OBSERVER(M) extern template class MvtObserver<M>;
NLOBS_FOR_EACH_CATALOGUE_MODEL(NLOBS_EXTERN_MVT_OBSERVER)
#undef NLOBS_EXTERN_MVT_OBSERVER

}  // namespace nlobs
