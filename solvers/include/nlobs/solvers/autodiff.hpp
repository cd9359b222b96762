#pragma once
// Forward-mode automatic differentiation through ceres::Jet (no AD of our own). The user
// function must be generic in its scalar type (a template or a generic lambda).
//   Compile-time N: one evaluation with ceres::Jet<double, N> — allocation-free.
//   Run-time n: ⌈n / kJetStride⌉ evaluations with ceres::Jet<double, kJetStride>, each seeding
//   kJetStride directions (the scheme of Ceres' DynamicAutoDiffCostFunction). Jets carry
//   fixed-size derivative vectors, so constants such as T(0.0) mix safely with variables —
//   unlike Eigen's AutoDiffScalar<VectorXd>, whose empty derivative vectors silently corrupt
//   Jacobians in such expressions.
#include <ceres/jet.h>

#include <algorithm>

#include "nlobs/solvers/callable.hpp"
#include "nlobs/solvers/types.hpp"

namespace nlobs {

inline constexpr int kJetStride = 8;

// J = ∂f/∂x at x, for f: R^N → R^M. For dynamic N the size comes from x, for dynamic M from
// the value f returns.
template <int N, int M, typename F>
void autodiff_jacobian(F& f, const Vector<N>& x, Matrix<M, N>& jacobian) {
  const Index n = x.size();
  if constexpr (N != Dynamic) {
    using Jet = ceres::Jet<double, N>;
    Vector<N, Jet> xj;
    for (Index j = 0; j < N; ++j) xj[j] = Jet(x[j], static_cast<int>(j));
    Vector<M, Jet> fj;
    if constexpr (M == Dynamic) fj.resize(jacobian.rows() > 0 ? jacobian.rows() : n);
    detail::invoke_map(f, xj, fj);
    jacobian.resize(fj.size(), N);
    for (Index i = 0; i < fj.size(); ++i) jacobian.row(i) = fj[i].v.transpose();
  } else {
    using Jet = ceres::Jet<double, kJetStride>;
    Vector<Dynamic, Jet> xj(n);
    Vector<M, Jet> fj;
    for (Index start = 0; start < n; start += kJetStride) {
      const Index width = std::min<Index>(kJetStride, n - start);
      for (Index j = 0; j < n; ++j) {
        xj[j] = Jet(x[j]);
        if (j >= start && j < start + width) xj[j].v[j - start] = 1.0;
      }
      if constexpr (M == Dynamic) fj.resize(jacobian.rows() > 0 ? jacobian.rows() : n);
      detail::invoke_map(f, xj, fj);
      if (start == 0) jacobian.resize(fj.size(), n);
      for (Index i = 0; i < fj.size(); ++i) {
        for (Index k = 0; k < width; ++k) jacobian(i, start + k) = fj[i].v[k];
      }
    }
  }
}

}  // namespace nlobs
