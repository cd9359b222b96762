#pragma once
// The Jacobians of a discrete model x⁺ = f(x, u, k), y = h(x) with respect to x, by forward-mode
// AD (ceres::Jet through autodiff_jacobian): what the EKF linearises with and the MHE's
// Gauss–Newton and arrival cost use. Fixed sizes allocate nothing.
#include <type_traits>

#include "nlobs/models/model.hpp"
#include "nlobs/solvers/autodiff.hpp"

namespace nlobs {

// F = ∂f/∂x at (x, u, k); `jacobian` is resized to n × n.
template <DiscreteModel Model>
void state_jacobian(const Model& model, const ModelVector<double, Model::kStates>& x,
                    const ModelVector<double, Model::kInputs>& u, long k,
                    Matrix<Model::kStates, Model::kStates>& jacobian) {
  auto f = [&model, &u, k](const auto& v) {
    using T = typename std::decay_t<decltype(v)>::Scalar;
    return ModelVector<T, Model::kStates>(model.f(ModelVector<T, Model::kStates>(v), u, k));
  };
  jacobian.resize(x.size(), x.size());
  autodiff_jacobian<Model::kStates, Model::kStates>(f, x, jacobian);
}

// H = ∂h/∂x at x; `jacobian` is resized to p × n.
template <DiscreteModel Model>
void output_jacobian(const Model& model, const ModelVector<double, Model::kStates>& x,
                     Matrix<Model::kOutputs, Model::kStates>& jacobian) {
  auto h = [&model](const auto& v) {
    using T = typename std::decay_t<decltype(v)>::Scalar;
    return ModelVector<T, Model::kOutputs>(model.h(ModelVector<T, Model::kStates>(v)));
  };
  jacobian.resize(model.outputs(), x.size());
  autodiff_jacobian<Model::kStates, Model::kOutputs>(h, x, jacobian);
}

}  // namespace nlobs
