#pragma once
// The Jacobians of a discrete model's move x⁺ = f(x, u, k) (or its flow over an interval,
// ModelStep) and of y = h(x) with respect to x, by forward-mode AD (ceres::Jet through
// autodiff_jacobian): what the EKF linearises with and the MHE's Gauss–Newton and arrival cost use.
// Fixed sizes allocate nothing.
#include <type_traits>

#include "nlobs/models/model.hpp"
#include "nlobs/observers/core/model_step.hpp"
#include "nlobs/solvers/autodiff.hpp"

namespace nlobs {

// F = ∂x⁺/∂x of the move s at (x, u); `jacobian` is resized to n × n.
template <DiscreteModel Model>
void state_jacobian(const Model& model, const ModelVector<double, Model::kStates>& x,
                    const ModelVector<double, Model::kInputs>& u, const ModelStep& s,
                    Matrix<Model::kStates, Model::kStates>& jacobian) {
  auto f = [&model, &u, &s](const auto& v) {
    using T = typename std::decay_t<decltype(v)>::Scalar;
    return advance(model, ModelVector<T, Model::kStates>(v), u, s);
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
