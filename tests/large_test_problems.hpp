#pragma once
// Two large sparse problems nlobs does not ship, written generic in the scalar type as a user
// writes for with_autodiff, shared by the sparse tests and bench/ (until `nlobs suite large`
// holds them), and the stop options the tests solve them with:
//   Broyden's tridiagonal function  F_i = (3 − 2x_i) x_i − x_{i−1} − 2x_{i+1} + 1,
//                                   x_0 = x_{n+1} = 0 (the returning call shape)
//   2-D Bratu (PETSc's SNES ex5)    (4u − Σ neighbours)/h² − λ e^u on an s×s interior grid,
//                                   h = 1/(s+1), u = 0 on the boundary (the out-parameter shape)
#include <cmath>
#include <type_traits>

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

// ‖F‖∞ ≤ residual_tolerance within max_iterations, the other stop rules at their defaults.
inline SolverOptions residual_stop(double residual_tolerance = 1e-10, int max_iterations = 100) {
  SolverOptions o;
  o.stop.residual_tolerance = residual_tolerance;
  o.stop.max_iterations = max_iterations;
  return o;
}

}  // namespace nlobs::test
