#pragma once
// Fixed-step discretisations x⁺ = f(x, u, k) of a continuous model, generic in the scalar
// (so window estimators, the EKF and the MHE differentiate them by AD, through every step):
// forward Euler (the fixed-point paper's) and classic RK4, with `substeps` steps of the scheme
// per sample. Adaptive integration in double goes through Boost.Odeint
// (odeint_discretization.hpp).
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "nlobs/common/invalid_input.hpp"
#include "nlobs/models/model.hpp"

namespace nlobs {

enum class Scheme { kEuler, kRk4 };

// How a continuous model is integrated over one sample of length h: `substeps` steps of
// `scheme`, each of length h / substeps. One step per sample is what the papers' examples use;
// a stiff or fast plant needs more (an explicit step is stable only while h / substeps times
// the largest |eigenvalue| of ∂F/∂x stays inside the scheme's region: 2 for Euler on the real
// axis, 2.79 for RK4, [HW96] §IV.2). The cost of f (and of its AD Jacobian) grows linearly.
// The scheme's default is Discretized's, Euler (the fixed-point paper's); the registry's models
// default to RK4 (ModelDefinition::default_scheme).
struct DiscretizationOptions {
  static constexpr int kMostSubsteps = 1000;
  Scheme scheme = Scheme::kEuler;
  int substeps = 1;  // 1 ≤ substeps ≤ kMostSubsteps

  // Throws InvalidInput naming the field when substeps is out of range.
  void validate() const {
    if (substeps >= 1 && substeps <= kMostSubsteps) return;
    throw InvalidInput("DiscretizationOptions::substeps = " + std::to_string(substeps) +
                       " is out of range [1, " + std::to_string(kMostSubsteps) + "]");
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
  // Throws InvalidInput for a step that is not finite and > 0 or options that do not validate.
  Discretized(Model model, double step, DiscretizationOptions options)
      : SampledModel<Model>(std::move(model), step), options_(options) {
    options_.validate();
  }

  Scheme scheme() const { return options_.scheme; }
  int substeps() const { return options_.substeps; }
  const DiscretizationOptions& options() const { return options_; }

  // x⁺ at t_{k+1} = (k + 1) h: the flow over one step from t_k = k h.
  template <typename T>
  State<T> f(const State<T>& x, const Input& u, long k) const {
    return flow(x, u, static_cast<double>(k) * this->step_, this->step_);
  }

  // x(t + dt) from x(t), u held: s = ⌈dt / δ⌉ steps of the scheme of equal length dt / s ≤ δ,
  // where δ = h / substeps (`substeps` steps of δ when dt = h, so that f is this flow on the
  // grid). Throws InvalidInput unless 0 ≤ dt ≤ 1e9 δ (a bounded number of steps).
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
    // A dt within rounding of a multiple of δ takes that many steps (no sliver of a step).
    const long steps = std::max(1L, static_cast<long>(std::ceil(in_steps - 1e-9)));
    const double h = dt / static_cast<double>(steps);
    State<T> state = x;
    for (long s = 0; s < steps; ++s, t += h) {
      if (options_.scheme == Scheme::kEuler) {
        state = State<T>(state + h * m.vector_field(state, u, t));
        continue;
      }
      const State<T> k1 = m.vector_field(state, u, t);
      const State<T> k2 = m.vector_field(State<T>(state + (h / 2) * k1), u, t + h / 2);
      const State<T> k3 = m.vector_field(State<T>(state + (h / 2) * k2), u, t + h / 2);
      const State<T> k4 = m.vector_field(State<T>(state + h * k3), u, t + h);
      state = State<T>(state + (h / 6) * (k1 + 2.0 * k2 + 2.0 * k3 + k4));
    }
    return state;
  }

 private:
  DiscretizationOptions options_;
};

}  // namespace nlobs
