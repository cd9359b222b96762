#pragma once
// Two large sparse problems nlobs does not ship, written generic in the scalar type as a user
// writes for with_autodiff, shared by the sparse tests and bench/ (until `nlobs suite large`
// holds them), and the stop options the tests solve them with:
//   Broyden's tridiagonal function  F_i = (3 − 2x_i) x_i − x_{i−1} − 2x_{i+1} + 1,
//                                   x_0 = x_{n+1} = 0 (the returning call shape)
//   2-D Bratu (PETSc's SNES ex5)    (4u − Σ neighbours)/h² − λ e^u on an s×s interior grid,
//                                   h = 1/(s+1), u = 0 on the boundary (the out-parameter shape)
// and a least-squares one, a smoothed exponential fit (smoothed_fit below).
#include <cmath>
#include <type_traits>
#include <utility>

#include "nlobs/solvers/engine.hpp"
#include "nlobs/solvers/types.hpp"

namespace nlobs::test {

inline auto broyden_tridiagonal() {
  return [](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    const Index n = x.size();
    Vector<Dynamic, T> f(n);
    for (Index i = 0; i < n; ++i) {
      f[i] = (3.0 - 2.0 * x[i]) * x[i] + 1.0;
      if (i > 0) f[i] -= x[i - 1];
      if (i + 1 < n) f[i] -= 2.0 * x[i + 1];
    }
    return f;
  };
}

inline auto bratu(Index s, double lambda = 6.0) {
  return [s, lambda](const auto& u, auto& f) {
    using T = typename std::decay_t<decltype(u)>::Scalar;
    using std::exp;
    const double h2 = 1.0 / static_cast<double>((s + 1) * (s + 1));
    f.resize(s * s);
    for (Index r = 0; r < s; ++r) {
      for (Index c = 0; c < s; ++c) {
        const Index p = r * s + c;
        T sum = 4.0 * u[p];
        if (r > 0) sum -= u[p - s];
        if (r + 1 < s) sum -= u[p + s];
        if (c > 0) sum -= u[p - 1];
        if (c + 1 < s) sum -= u[p + 1];
        f[p] = sum / h2 - lambda * exp(u[p]);
      }
    }
  };
}

// A nonlinear least-squares problem with no zero residual, m = 2n − 1:
//   r_i = exp(x_i) + 0.1 x_i x_{i+1} − d_i (i < n, x_n = 0),  r_{n+i} = α (x_{i+1} − x_i),
// data d from x*_i = sin(i/7) perturbed by 0.05 cos(2.9 i), which the smoothing term cannot
// follow: the minimum leaves residuals of order 1e-2. J has 2 entries a row.
inline Vector<Dynamic> smoothed_fit_data(Index n) {
  Vector<Dynamic> data(n);
  for (Index i = 0; i < n; ++i) {
    const double xi = std::sin(static_cast<double>(i) / 7.0);
    const double next = i + 1 < n ? std::sin(static_cast<double>(i + 1) / 7.0) : 0.0;
    data[i] = std::exp(xi) + 0.1 * xi * next + 0.05 * std::cos(2.9 * static_cast<double>(i));
  }
  return data;
}

inline auto smoothed_fit(Vector<Dynamic> data, double alpha = 0.5) {
  return [d = std::move(data), alpha](const auto& x, auto& r) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    using std::exp;
    const Index size = x.size();
    r.resize(2 * size - 1);
    for (Index i = 0; i < size; ++i) {
      const T next = i + 1 < size ? T(x[i + 1]) : T(0.0);
      r[i] = exp(x[i]) + 0.1 * x[i] * next - d[i];
      if (i + 1 < size) r[size + i] = alpha * (x[i + 1] - x[i]);
    }
  };
}

// ‖F‖∞ ≤ residual_tolerance within max_iterations, the other stop rules at their defaults.
inline SolverOptions residual_stop(double residual_tolerance = 1e-10, int max_iterations = 100) {
  SolverOptions o;
  o.stop.residual_tolerance = residual_tolerance;
  o.stop.max_iterations = max_iterations;
  return o;
}

}  // namespace nlobs::test
