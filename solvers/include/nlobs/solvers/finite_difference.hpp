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

// jac = ∂G(x); gx = G(x) is reused by the forward scheme. Returns the G evaluations spent.
template <int N>
int finite_difference_jacobian(const FixedPointProblem<N>& problem, const Vector<N>& x,
                               const Vector<N>& gx, Matrix<N, N>& jac, FiniteDifference scheme,
                               FiniteDifferenceWorkspace<N>& work) {
  const double c = scheme == FiniteDifference::kForward
                       ? std::sqrt(std::numeric_limits<double>::epsilon())
                       : std::cbrt(std::numeric_limits<double>::epsilon());
  const Index n = x.size();
  if constexpr (N == Dynamic) jac.resize(n, n);
  int evaluations = 0;
  work.xp = x;
  for (Index j = 0; j < n; ++j) {
    const double h_raw = c * std::max(1.0, std::abs(x[j]));
    work.xp[j] = x[j] + h_raw;
    const double h = work.xp[j] - x[j];
    problem.evaluate(work.xp, work.gp);
    ++evaluations;
    if (scheme == FiniteDifference::kForward) {
      jac.col(j) = (work.gp - gx) / h;
    } else {
      work.xp[j] = x[j] - h;
      problem.evaluate(work.xp, work.gm);
      ++evaluations;
      jac.col(j) = (work.gp - work.gm) / (2.0 * h);
    }
    work.xp[j] = x[j];
  }
  return evaluations;
}

}  // namespace nlobs
