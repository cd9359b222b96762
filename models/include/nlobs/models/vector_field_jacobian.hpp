#pragma once
// J = ∂F/∂x (x, u, t) of a continuous model in double, by forward-mode AD through ceres::Jet:
// what an implicit scheme's Newton iteration and its implicit-function derivative use
// (sdirk.hpp). Compile-time n: one evaluation on Jet<double, n>. Run-time n: ⌈n / 8⌉
// evaluations on Jet<double, 8>, eight directions each — the scalars the observers already
// evaluate the model on (solvers/autodiff.hpp), so no new instantiation of the model's code.
#include <ceres/jet.h>

#include <Eigen/Core>
#include <algorithm>

#include "nlobs/models/model.hpp"

namespace nlobs {

template <ContinuousModel Model>
void vector_field_jacobian(const Model& model, const ModelVector<double, Model::kStates>& x,
                           const ModelVector<double, Model::kInputs>& u, double t,
                           Eigen::Matrix<double, Model::kStates, Model::kStates>& jacobian) {
  constexpr int N = Model::kStates;
  const Eigen::Index n = x.size();
  jacobian.resize(n, n);
  if constexpr (N != Eigen::Dynamic) {
    using Jet = ceres::Jet<double, N>;
    ModelVector<Jet, N> xj;
    for (int j = 0; j < N; ++j) xj[j] = Jet(x[j], j);
    const ModelVector<Jet, N> fj = model.vector_field(xj, u, t);
    for (int i = 0; i < N; ++i) jacobian.row(i) = fj[i].v.transpose();
  } else {
    constexpr int kStride = 8;  // solvers/autodiff.hpp's kJetStride
    using Jet = ceres::Jet<double, kStride>;
    ModelVector<Jet, N> xj(n);
    for (Eigen::Index start = 0; start < n; start += kStride) {
      const Eigen::Index width = std::min<Eigen::Index>(kStride, n - start);
      for (Eigen::Index j = 0; j < n; ++j) {
        xj[j] = Jet(x[j]);
        if (j >= start && j < start + width) xj[j].v[j - start] = 1.0;
      }
      const ModelVector<Jet, N> fj = model.vector_field(xj, u, t);
      for (Eigen::Index i = 0; i < n; ++i) {
        for (Eigen::Index k = 0; k < width; ++k) jacobian(i, start + k) = fj[i].v[k];
      }
    }
  }
}

}  // namespace nlobs
