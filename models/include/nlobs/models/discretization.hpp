#pragma once
// Fixed-step discretisations x⁺ = f(x, u, k) of a continuous model, generic in the scalar
// (so window estimators can differentiate them): forward Euler (the fixed-point paper's) and
// classic RK4. Adaptive and stiff integration go through Boost.Odeint (odeint_discretization.hpp).
#include <sstream>
#include <stdexcept>
#include <string>

#include "nlobs/models/model.hpp"

namespace nlobs {

enum class Scheme { kEuler, kRk4 };

template <ContinuousModel Model>
class Discretized {
 public:
  static constexpr int kStates = Model::kStates;
  static constexpr int kInputs = Model::kInputs;
  static constexpr int kOutputs = Model::kOutputs;
  template <typename T>
  using State = ModelVector<T, kStates>;
  using Input = ModelVector<double, kInputs>;

  // Throws std::invalid_argument when the step is not finite and > 0.
  Discretized(Model model, double step, Scheme scheme = Scheme::kEuler)
      : model_(std::move(model)), step_(step), scheme_(scheme) {
    if (!(step_ > 0.0) || !std::isfinite(step_)) {
      std::ostringstream os;
      os << "discretisation step = " << step_ << " is invalid: must be finite and > 0";
      throw std::invalid_argument(os.str());
    }
  }

  const Model& model() const { return model_; }
  double step() const { return step_; }
  Scheme scheme() const { return scheme_; }
  Eigen::Index states() const { return model_.states(); }
  Eigen::Index inputs() const { return model_.inputs(); }
  Eigen::Index outputs() const { return model_.outputs(); }

  template <typename T>
  State<T> f(const State<T>& x, const Input& u, long k) const {
    const double t = static_cast<double>(k) * step_, h = step_;
    if (scheme_ == Scheme::kEuler) return x + h * model_.vector_field(x, u, t);
    const State<T> k1 = model_.vector_field(x, u, t);
    const State<T> k2 = model_.vector_field(State<T>(x + (h / 2) * k1), u, t + h / 2);
    const State<T> k3 = model_.vector_field(State<T>(x + (h / 2) * k2), u, t + h / 2);
    const State<T> k4 = model_.vector_field(State<T>(x + h * k3), u, t + h);
    return x + (h / 6) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  }

  template <typename T>
  auto h(const State<T>& x) const {
    return model_.h(x);
  }

  std::string domain_violation(const State<double>& x) const {
    return domain_violation_of(model_, x);
  }

 private:
  Model model_;
  double step_;
  Scheme scheme_;
};

}  // namespace nlobs
