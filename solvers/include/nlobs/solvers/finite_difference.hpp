#pragma once
// Finite-difference ∂G for problems without a Jacobian. Steps h_j = c · max(1, |x_j|) with
// c = √ε (forward, error O(h)) or ∛ε (central, error O(h²)), rounded so that x_j + h_j − x_j = h_j
// exactly.
// Inside a box (a bounded solve) no point leaves it, nor reaches a strict bound (the room towards
// one is half the distance to it): a forward step that would cross a bound is
// taken backwards; a central pair that would is replaced by the one-sided second-order formula
// (−3 f(x) + 4 f(x + h) − f(x + 2h)) / 2h towards the side with room, h shrunk to fit if needed
// (same cost, same order); a component that cannot move (lower = upper, or within a few ulps of
// a bound on the only side with room, where x_j ± h rounds to x_j) gets a zero column.
#include <algorithm>
#include <cmath>
#include <limits>

#include "nlobs/solvers/box_bounds.hpp"
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
// and one-sided schemes. `work` holds the perturbed point and values; `box`, when given and
// active, holds every point evaluated. Returns the evaluations of f spent: n forward, 2n central
// (fewer where lower = upper).
template <int N, int M, typename F>
int finite_difference_jacobian(F&& f, const Vector<N>& x, const Vector<M>& fx, Matrix<M, N>& jac,
                               FiniteDifference scheme, FiniteDifferenceWorkspace<N>& xwork,
                               Vector<M>& fp, Vector<M>& fm, const detail::Box<N>* box = nullptr) {
  const double c = scheme == FiniteDifference::kForward
                       ? std::sqrt(std::numeric_limits<double>::epsilon())
                       : std::cbrt(std::numeric_limits<double>::epsilon());
  const Index n = x.size();
  if constexpr (N == Dynamic || M == Dynamic) jac.resize(fx.size(), n);
  const bool bounded = box && box->active();
  int evaluations = 0;
  Vector<N>& xp = xwork.xp;
  xp = x;
  for (Index j = 0; j < n; ++j) {
    double h = c * std::max(1.0, std::abs(x[j]));
    double direction = 1.0;
    bool one_sided = false;
    if (bounded) {
      const double lo = box->lower()[j], hi = box->upper()[j];
      // The room on each side, ≥ 0 (half the distance to a strict bound).
      const double up = box->room_above(j, x[j]), down = box->room_below(j, x[j]);
      const bool forward = scheme == FiniteDifference::kForward;
      if (forward ? h > up : (h > up || h > down)) {
        direction = up >= down ? 1.0 : -1.0;
        one_sided = !forward;
        h = std::min(h, std::max(up, down) / (forward ? 1.0 : 2.0));
      }
      if (!(h > 0.0)) {  // lower = upper: x_j cannot move
        jac.col(j).setZero();
        continue;
      }
      xp[j] = std::clamp(x[j] + direction * h, lo, hi);
      const double far = std::clamp(x[j] + 2.0 * direction * h, lo, hi);
      if (xp[j] == x[j] || box->on_strict_bound(j, xp[j]) ||
          (one_sided && box->on_strict_bound(j, far))) {
        // Within a few ulps of a strict bound on the only side with room: no point to take.
        xp[j] = x[j];
        jac.col(j).setZero();
        continue;
      }
    } else {
      xp[j] = x[j] + h;
    }
    const double step = xp[j] - x[j];  // exactly representable, signed
    f(xp, fp);
    ++evaluations;
    if (scheme == FiniteDifference::kForward) {
      jac.col(j) = (fp - fx) / step;
    } else if (one_sided) {
      xp[j] = std::clamp(x[j] + 2.0 * step, box->lower()[j], box->upper()[j]);
      f(xp, fm);
      ++evaluations;
      jac.col(j) = (4.0 * fp - 3.0 * fx - fm) / (2.0 * step);
    } else {
      xp[j] = x[j] - step;
      f(xp, fm);
      ++evaluations;
      jac.col(j) = (fp - fm) / (2.0 * step);
    }
    xp[j] = x[j];
  }
  return evaluations;
}

// ∂G of a fixed-point problem; gx = G(x).
template <int N>
int finite_difference_jacobian(const FixedPointProblem<N>& problem, const Vector<N>& x,
                               const Vector<N>& gx, Matrix<N, N>& jac, FiniteDifference scheme,
                               FiniteDifferenceWorkspace<N>& work,
                               const detail::Box<N>* box = nullptr) {
  return finite_difference_jacobian<N, N>(
      [&problem](const Vector<N>& at, Vector<N>& out) { problem.evaluate(at, out); }, x, gx, jac,
      scheme, work, work.gp, work.gm, box);
}

}  // namespace nlobs
