#pragma once
// Fixed-step discretisations x⁺ = f(x, u, k) of a continuous model, generic in the scalar
// (so window estimators can differentiate them): forward Euler (the fixed-point paper's) and
// classic RK4. Adaptive and stiff integration go through Boost.Odeint (odeint_discretization.hpp).
#include <sstream>
#include <string>

#include "nlobs/common/invalid_input.hpp"
#include "nlobs/models/model.hpp"

namespace nlobs {

enum class Scheme { kEuler, kRk4 };

// What every discretisation of a continuous model shares: the model, the sample step h
// (t_k = k h), sizes, the output map and the domain.
template <ContinuousModel Model>
class SampledModel {
 public:
  static constexpr int kStates = Model::kStates;
  static constexpr int kInputs = Model::kInputs;
  static constexpr int kOutputs = Model::kOutputs;
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
      : SampledModel<Model>(std::move(model), step), scheme_(scheme) {}

  Scheme scheme() const { return scheme_; }

  template <typename T>
  State<T> f(const State<T>& x, const Input& u, long k) const {
    const Model& m = this->model_;
    const double t = static_cast<double>(k) * this->step_, h = this->step_;
    if (scheme_ == Scheme::kEuler) return x + h * m.vector_field(x, u, t);
    const State<T> k1 = m.vector_field(x, u, t);
    const State<T> k2 = m.vector_field(State<T>(x + (h / 2) * k1), u, t + h / 2);
    const State<T> k3 = m.vector_field(State<T>(x + (h / 2) * k2), u, t + h / 2);
    const State<T> k4 = m.vector_field(State<T>(x + h * k3), u, t + h);
    return x + (h / 6) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  }

 private:
  Scheme scheme_;
};

}  // namespace nlobs
