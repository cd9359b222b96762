#pragma once
// Derivatives of a continuous model's vector field F(x, u, t) with respect to x, for observers
// that need them at run time (the MVT observer): the full Jacobian ∂F/∂x and the directional
// derivative ∂F/∂x · d. By forward-mode AD through ceres::Jet when the model's vector field is
// generic in its scalar; by central differences otherwise (an observer says so in a warning).
// Fixed sizes only: nothing here allocates.
#include <ceres/jet.h>

#include <Eigen/Core>
#include <cmath>
#include <concepts>
#include <limits>

#include "nlobs/models/model.hpp"

namespace nlobs {

// True when `vector_field` accepts ceres::Jet states (the model can be differentiated by AD).
template <typename Model>
concept JetDifferentiable = requires(
    const Model m, const ModelVector<ceres::Jet<double, Model::kStates>, Model::kStates>& x,
    const ModelVector<double, Model::kInputs>& u) {
  // The result must be Jet-valued: a double-only vector field would accept the Jets through
  // Eigen's converting constructor and fail only when instantiated.
  {
    m.vector_field(x, u, 0.0)
    } -> std::same_as<ModelVector<ceres::Jet<double, Model::kStates>, Model::kStates>>;
};

template <ContinuousModel Model>
class ModelDerivatives {
 public:
  static constexpr int N = Model::kStates;
  static_assert(N != Eigen::Dynamic, "ModelDerivatives needs a model with a compile-time size");
  using State = ModelVector<double, N>;
  using Input = ModelVector<double, Model::kInputs>;
  using Jacobian = Eigen::Matrix<double, N, N>;
  static constexpr bool kAutoDiff = JetDifferentiable<Model>;

  explicit ModelDerivatives(const Model& model) : model_(&model) {}

  State value(const State& x, const Input& u, double t) const {
    return model_->vector_field(x, u, t);
  }

  // J = ∂F/∂x at x.
  void jacobian(const State& x, const Input& u, double t, Jacobian& j) const {
    if constexpr (kAutoDiff) {
      using Jet = ceres::Jet<double, N>;
      ModelVector<Jet, N> xj;
      for (int i = 0; i < N; ++i) xj[i] = Jet(x[i], i);
      const ModelVector<Jet, N> fj = model_->vector_field(xj, u, t);
      for (int i = 0; i < N; ++i) j.row(i) = fj[i].v.transpose();
    } else {
      State xp = x, xm = x;
      for (int k = 0; k < N; ++k) {
        const double h = step(x[k]);
        xp[k] = x[k] + h;
        xm[k] = x[k] - h;
        j.col(k) = (model_->vector_field(xp, u, t) - model_->vector_field(xm, u, t)) / (2.0 * h);
        xp[k] = xm[k] = x[k];
      }
    }
  }

  // ∂F/∂x(x) · d, every row.
  State directional(const State& x, const State& d, const Input& u, double t) const {
    if constexpr (kAutoDiff) {
      using Jet = ceres::Jet<double, 1>;
      ModelVector<Jet, N> xj;
      for (int i = 0; i < N; ++i) {
        xj[i] = Jet(x[i]);
        xj[i].v[0] = d[i];
      }
      const ModelVector<Jet, N> fj = model_->vector_field(xj, u, t);
      State out;
      for (int i = 0; i < N; ++i) out[i] = fj[i].v[0];
      return out;
    } else {
      const double scale = d.template lpNorm<Eigen::Infinity>();
      if (scale == 0.0) return State::Zero();
      const double h = step(x.template lpNorm<Eigen::Infinity>()) / scale;
      return (model_->vector_field(State(x + h * d), u, t) -
              model_->vector_field(State(x - h * d), u, t)) /
             (2.0 * h);
    }
  }

 private:
  // Central differences: h ∝ ε^{1/3} balances truncation against rounding.
  static double step(double magnitude) {
    return std::cbrt(std::numeric_limits<double>::epsilon()) * std::max(1.0, std::abs(magnitude));
  }
  const Model* model_;
};

}  // namespace nlobs
