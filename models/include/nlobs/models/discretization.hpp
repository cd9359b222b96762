#pragma once
// Discretisations x⁺ = f(x, u, k) of a continuous model, generic in the scalar (so window
// estimators, the EKF and the MHE differentiate them by AD, through every step), by one of four
// schemes chosen per model:
//   euler   forward Euler (the fixed-point paper's), `substeps` steps per sample;
//   rk4     classic Runge–Kutta, `substeps` steps per sample;
//   dopri5  adaptive Dormand–Prince 5(4) with error control (dormand_prince.hpp), steps of at
//           most h / substeps;
//   sdirk3  implicit, L-stable SDIRK of order 3 for stiff plants (sdirk.hpp), `substeps` steps
//           per sample, dense Newton (n ≤ kMostImplicitStates = 200).
// Adaptive integration in double only goes through Boost.Odeint (odeint_discretization.hpp).
#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>

#include "nlobs/common/invalid_input.hpp"
#include "nlobs/models/dormand_prince.hpp"
#include "nlobs/models/model.hpp"
#include "nlobs/models/sdirk.hpp"

namespace nlobs {

enum class Scheme { kEuler, kRk4, kDopri5, kSdirk3 };

inline constexpr std::string_view kSchemeNames = "euler, rk4, dopri5, sdirk3";

// "euler", "rk4", "dopri5", "sdirk3": the model spec's "scheme".
inline std::string_view scheme_name(Scheme scheme) {
  switch (scheme) {
    case Scheme::kEuler:
      return "euler";
    case Scheme::kRk4:
      return "rk4";
    case Scheme::kDopri5:
      return "dopri5";
    case Scheme::kSdirk3:
      return "sdirk3";
  }
  return "?";
}

// The scheme a name in kSchemeNames gives; nullopt for any other text.
inline std::optional<Scheme> scheme_from_name(std::string_view name) {
  for (Scheme s : {Scheme::kEuler, Scheme::kRk4, Scheme::kDopri5, Scheme::kSdirk3}) {
    if (scheme_name(s) == name) return s;
  }
  return std::nullopt;
}

// How a continuous model is integrated over one sample of length h. One explicit step per
// sample is what the papers' examples use; a stiff or fast plant needs more: an explicit step
// is stable only while its length times the largest |eigenvalue| of ∂F/∂x stays inside the
// scheme's region (2 for Euler on the real axis, 2.79 for RK4, 3.3 for Dormand–Prince,
// [HW96] §IV.2), so `substeps` steps of δ = h / substeps, the error control of dopri5 (which
// finds δ where it must, at a cost per sample that grows with the stiffness), or sdirk3, whose
// L-stability holds at any δ (an n × n LU per step instead). The cost of f and of its AD
// Jacobian grows linearly with the steps. The scheme's default is Discretized's, Euler (the
// fixed-point paper's); the registry's models default to RK4 (ModelDefinition::default_scheme).
struct DiscretizationOptions {
  static constexpr int kMostSubsteps = 1000;
  static constexpr long kMostImplicitStates = 200;  // sdirk3: dense, AD in O(n⁴ / 8) (sdirk.hpp)
  Scheme scheme = Scheme::kEuler;
  // 1 ≤ substeps ≤ kMostSubsteps: steps of h / substeps per sample; dopri5: its first and
  // largest step h / substeps.
  int substeps = 1;
  // dopri5's local error control, err_i ≤ atol + rtol |x_i| (dormand_prince.hpp); sdirk3's
  // Newton increment ≤ 1 % of it (sdirk.hpp). Unused by euler and rk4.
  double absolute_tolerance = 1e-8;  // finite, > 0
  double relative_tolerance = 1e-6;  // in [1e-12, 1]

  // Throws InvalidInput naming the field when one is out of range.
  void validate() const {
    std::ostringstream os;
    if (substeps < 1 || substeps > kMostSubsteps) {
      os << "DiscretizationOptions::substeps = " << substeps << " is out of range [1, "
         << kMostSubsteps << "]";
    } else if (!(absolute_tolerance > 0.0) || !std::isfinite(absolute_tolerance)) {
      os << "DiscretizationOptions::absolute_tolerance = " << absolute_tolerance
         << " must be finite and > 0";
    } else if (!(relative_tolerance >= 1e-12 && relative_tolerance <= 1.0)) {
      os << "DiscretizationOptions::relative_tolerance = " << relative_tolerance
         << " is out of range [1e-12, 1]";
    } else {
      return;
    }
    throw InvalidInput(os.str());
  }
};

// What every discretisation of a continuous model shares: the model, the sample step h
// (t_k = k h), sizes, the output map and the domain.
template <ContinuousModel Model>
class SampledModel {
 public:
  static constexpr int kStates = Model::kStates;
  static constexpr int kInputs = Model::kInputs;
  static constexpr int kOutputs = Model::kOutputs;
  static constexpr bool kTracesSparsity = traces_sparsity<Model>();
  template <typename T>
  using State = ModelVector<T, kStates>;
  using Input = ModelVector<double, kInputs>;

  const Model& model() const { return model_; }
  double step() const { return step_; }
  Eigen::Index states() const { return model_.states(); }
  Eigen::Index inputs() const { return model_.inputs(); }
  Eigen::Index outputs() const { return model_.outputs(); }

  template <typename T>
  auto h(const State<T>& x) const {
    return model_.h(x);
  }

  std::string domain_violation(const State<double>& x) const {
    return domain_violation_of(model_, x);
  }

 protected:
  // Throws InvalidInput when the step is not finite and > 0.
  SampledModel(Model model, double step) : model_(std::move(model)), step_(step) {
    if (!(step_ > 0.0) || !std::isfinite(step_)) {
      std::ostringstream os;
      os << "discretisation step = " << step_ << " is invalid: must be finite and > 0";
      throw InvalidInput(os.str());
    }
  }
  Model model_;
  double step_;
};

template <ContinuousModel Model>
class Discretized : public SampledModel<Model> {
 public:
  using typename SampledModel<Model>::Input;
  template <typename T>
  using State = typename SampledModel<Model>::template State<T>;

  Discretized(Model model, double step, Scheme scheme = Scheme::kEuler)
      : Discretized(std::move(model), step, DiscretizationOptions{.scheme = scheme}) {}
  // Throws InvalidInput for a step that is not finite and > 0, options that do not validate, or
  // sdirk3 on more than kMostImplicitStates states.
  Discretized(Model model, double step, DiscretizationOptions options)
      : SampledModel<Model>(std::move(model), step), options_(options) {
    options_.validate();
    if (options_.scheme == Scheme::kSdirk3 &&
        this->states() > DiscretizationOptions::kMostImplicitStates) {
      throw InvalidInput("scheme sdirk3 factors a dense n x n matrix per step: n = " +
                         std::to_string(this->states()) + " states is above its limit of " +
                         std::to_string(DiscretizationOptions::kMostImplicitStates) +
                         " (use rk4 or dopri5 with substeps)");
    }
  }

  Scheme scheme() const { return options_.scheme; }
  int substeps() const { return options_.substeps; }
  const DiscretizationOptions& options() const { return options_; }

  // Whether one evaluation on SparsityTracer scalars finds the pattern of every move
  // (models/model.hpp, traces_sparsity_now): the fixed explicit steps. dopri5's number of steps
  // depends on the values, and sdirk3's move is dense.
  bool traceable() const {
    return options_.scheme == Scheme::kEuler || options_.scheme == Scheme::kRk4;
  }

  // x⁺ at t_{k+1} = (k + 1) h: the flow over one step from t_k = k h.
  template <typename T>
  State<T> f(const State<T>& x, const Input& u, long k) const {
    return flow(x, u, static_cast<double>(k) * this->step_, this->step_);
  }

  // x(t + dt) from x(t), u held. euler, rk4, sdirk3: s = ⌈dt / δ⌉ steps of equal length
  // dt / s ≤ δ, where δ = h / substeps (`substeps` steps of δ when dt = h, so that f is this
  // flow on the grid); dopri5: steps of at most δ chosen by its error control. Throws
  // InvalidInput unless 0 ≤ dt ≤ 1e9 δ (a bounded number of steps), and IntegrationFailure when
  // dopri5's or sdirk3's control gives up (dormand_prince.hpp, sdirk.hpp).
  template <typename T>
  State<T> flow(const State<T>& x, const Input& u, double t, double dt) const {
    const double in_steps = dt / this->step_ * options_.substeps;  // dt / δ
    if (!(dt >= 0.0) || !(in_steps <= 1e9)) {
      std::ostringstream os;
      os << "Discretized::flow: dt = " << dt << " must be >= 0 and at most 1e9 steps of h / "
         << "substeps = " << this->step_ << " / " << options_.substeps;
      throw InvalidInput(os.str());
    }
    const Model& m = this->model_;
    if (options_.scheme == Scheme::kDopri5) {
      return dormand_prince_flow(
          m, x, u, t, dt,
          AdaptiveStepControl{.largest_step = this->step_ / options_.substeps,
                              .absolute_tolerance = options_.absolute_tolerance,
                              .relative_tolerance = options_.relative_tolerance});
    }
    // A dt within rounding of a multiple of δ takes that many steps (no sliver of a step).
    const long steps = std::max(1L, static_cast<long>(std::ceil(in_steps - 1e-9)));
    const double h = dt / static_cast<double>(steps);
    State<T> state = x;
    for (long s = 0; s < steps; ++s, t += h) {
      switch (options_.scheme) {
        case Scheme::kEuler:
          state = State<T>(state + h * m.vector_field(state, u, t));
          break;
        case Scheme::kSdirk3:
          state =
              sdirk3_step(m, state, u, t, h,
                          ImplicitStepControl{.absolute_tolerance = options_.absolute_tolerance,
                                              .relative_tolerance = options_.relative_tolerance});
          break;
        case Scheme::kRk4:
        default: {
          const State<T> k1 = m.vector_field(state, u, t);
          const State<T> k2 = m.vector_field(State<T>(state + (h / 2) * k1), u, t + h / 2);
          const State<T> k3 = m.vector_field(State<T>(state + (h / 2) * k2), u, t + h / 2);
          const State<T> k4 = m.vector_field(State<T>(state + h * k3), u, t + h);
          state = State<T>(state + (h / 6) * (k1 + 2.0 * k2 + 2.0 * k3 + k4));
        }
      }
    }
    return state;
  }

 private:
  DiscretizationOptions options_;
};

}  // namespace nlobs
