#pragma once
// Forward-mode automatic differentiation through existing libraries (no AD of our own):
// ceres::Jet<double, N> for compile-time sizes (allocation-free), Eigen's AutoDiffScalar
// with a dynamic derivative vector for run-time sizes. The user function must be generic in
// its scalar type (a template or a generic lambda).
#include <ceres/jet.h>

#include <unsupported/Eigen/AutoDiff>

#include "nlobs/solvers/callable.hpp"
#include "nlobs/solvers/types.hpp"

namespace nlobs {

// J = ∂f/∂x at x, for f: R^N → R^M. For dynamic N the size comes from x, for dynamic M
// from the value f returns.
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
    using Ad = Eigen::AutoDiffScalar<Eigen::VectorXd>;
    Vector<Dynamic, Ad> xa(n);
    for (Index j = 0; j < n; ++j) xa[j] = Ad(x[j], static_cast<int>(n), static_cast<int>(j));
    Vector<M, Ad> fa;
    if constexpr (M == Dynamic) fa.resize(jacobian.rows() > 0 ? jacobian.rows() : n);
    detail::invoke_map(f, xa, fa);
    jacobian.resize(fa.size(), n);
    for (Index i = 0; i < fa.size(); ++i) {
      // An output that does not depend on x carries an empty derivative vector.
      if (fa[i].derivatives().size() == n) {
        jacobian.row(i) = fa[i].derivatives().transpose();
      } else {
        jacobian.row(i).setZero();
      }
    }
  }
}

}  // namespace nlobs
