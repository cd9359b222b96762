#pragma once
// Finite-difference ∂G for problems without a Jacobian. Steps h_j = c · max(1, |x_j|) with
// c = √ε (forward, error O(h)) or ∛ε (central, error O(h²)), rounded so that x_j + h_j − x_j = h_j
// exactly.
#include <algorithm>
#include <cmath>
#include <limits>

#include "nlobs/solvers/problem.hpp"

namespace nlobs {

enum class FiniteDifference { kForward, kCentral };

template <int N>
struct FiniteDifferenceWorkspace {
  Vector<N> xp, gp, gm;
  void resize(Index n) { xp.resize(n), gp.resize(n), gm.resize(n); }
};

// Evaluations one difference Jacobian of n unknowns costs: n forward, 2n central.
inline int finite_difference_cost(FiniteDifference scheme, Index n) {
  return static_cast<int>(scheme == FiniteDifference::kForward ? n : 2 * n);
}

// jac = ∂f(x) for any f: R^N → R^M called as f(x, out); fx = f(x) is reused by the forward
// scheme. `work` holds the perturbed point and values. Returns the evaluations of f spent.
template <int N, int M, typename F>
int finite_difference_jacobian(F&& f, const Vector<N>& x, const Vector<M>& fx, Matrix<M, N>& jac,
                               FiniteDifference scheme, FiniteDifferenceWorkspace<N>& xwork,
                               Vector<M>& fp, Vector<M>& fm) {
  const double c = scheme == FiniteDifference::kForward
                       ? std::sqrt(std::numeric_limits<double>::epsilon())
                       : std::cbrt(std::numeric_limits<double>::epsilon());
  const Index n = x.size();
  if constexpr (N == Dynamic || M == Dynamic) jac.resize(fx.size(), n);
  int evaluations = 0;
  Vector<N>& xp = xwork.xp;
  xp = x;
  for (Index j = 0; j < n; ++j) {
    xp[j] = x[j] + c * std::max(1.0, std::abs(x[j]));
    const double h = xp[j] - x[j];  // exactly representable step
    f(xp, fp);
    ++evaluations;
    if (scheme == FiniteDifference::kForward) {
      jac.col(j) = (fp - fx) / h;
    } else {
      xp[j] = x[j] - h;
      f(xp, fm);
      ++evaluations;
      jac.col(j) = (fp - fm) / (2.0 * h);
    }
    xp[j] = x[j];
  }
  return evaluations;
}

// ∂G of a fixed-point problem; gx = G(x).
template <int N>
int finite_difference_jacobian(const FixedPointProblem<N>& problem, const Vector<N>& x,
                               const Vector<N>& gx, Matrix<N, N>& jac, FiniteDifference scheme,
                               FiniteDifferenceWorkspace<N>& work) {
  return finite_difference_jacobian<N, N>(
      [&problem](const Vector<N>& at, Vector<N>& out) { problem.evaluate(at, out); }, x, gx, jac,
      scheme, work, work.gp, work.gm);
}

}  // namespace nlobs
