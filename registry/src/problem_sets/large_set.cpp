#include "nlobs/registry/problem_sets/large_set.hpp"

#include <algorithm>
#include <cmath>
#include <type_traits>

namespace nlobs {
namespace {

// The side of a square grid of about n points, at least `smallest`.
Index grid_side(Index n, Index smallest) {
  return std::max(smallest, static_cast<Index>(std::llround(std::sqrt(static_cast<double>(n)))));
}

ProblemStart constant_start(Index n, double value) {
  return {"x0", Eigen::VectorXd::Constant(n, value)};
}

TestProblem broyden_tridiagonal(Index n) {
  auto f = [](const auto& x, auto& out) {
    const Index size = x.size();
    for (Index i = 0; i < size; ++i) {
      out[i] = (3.0 - 2.0 * x[i]) * x[i] + 1.0;
      if (i > 0) out[i] -= x[i - 1];
      if (i + 1 < size) out[i] -= 2.0 * x[i + 1];
    }
  };
  TestProblem p = root_test_problem("broyden-tridiagonal", n, f, {constant_start(n, -1.0)});
  p.description = "Broyden's tridiagonal function from -1 (MGH 30)";
  return p;
}

TestProblem bratu2d(Index wanted) {
  const Index m = grid_side(wanted, 4);
  const double h = 1.0 / static_cast<double>(m - 1);
  const double sc = h * h * 6.0;  // h² λ, λ = 6
  auto f = [m, sc](const auto& u, auto& out) {
    using std::exp;
    using T = typename std::decay_t<decltype(u)>::Scalar;
    for (Index j = 0; j < m; ++j) {
      for (Index i = 0; i < m; ++i) {
        const Index k = j * m + i;
        if (i == 0 || j == 0 || i == m - 1 || j == m - 1) {
          out[k] = 4.0 * u[k];
          continue;
        }
        // Boundary neighbours are the boundary values, 0 (ex5: a symmetric Jacobian).
        T r = 4.0 * u[k] - sc * exp(u[k]);
        if (i > 1) r -= u[k - 1];
        if (i < m - 2) r -= u[k + 1];
        if (j > 1) r -= u[k - m];
        if (j < m - 2) r -= u[k + m];
        out[k] = r;
      }
    }
  };
  TestProblem p = root_test_problem("bratu2d", m * m, f, {constant_start(m * m, 0.0)});
  p.description = "2-D Bratu, lambda = 6, " + std::to_string(m) + "x" + std::to_string(m) +
                  " grid (PETSc SNES ex5)";
  return p;
}

// reaction-diffusion1d's constants: κ, s and d.
constexpr double kReaction = 100.0, kSource = 100.0, kDiffusionV = 0.1;

TestProblem reaction_diffusion1d(Index wanted) {
  const Index points = std::max<Index>(2, wanted / 2);
  const double h = 1.0 / static_cast<double>(points + 1);
  auto f = [points, h](const auto& x, auto& out) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    for (Index i = 0; i < points; ++i) {
      const Index a = 2 * i, b = a + 1;  // u_i, v_i
      T du = 2.0 * x[a], dv = 2.0 * x[b];
      if (i > 0) {
        du -= x[a - 2];
        dv -= x[b - 2];
      }
      if (i + 1 < points) {
        du -= x[a + 2];
        dv -= x[b + 2];
      }
      out[a] = du / h + h * (kReaction * (x[a] * x[a] * x[a] + x[a] - x[b]) - kSource);
      out[b] = kDiffusionV * dv / h + h * kReaction * (x[b] * x[b] * x[b] + x[b] - x[a]);
    }
  };
  const Index n = 2 * points;
  TestProblem p = root_test_problem("reaction-diffusion1d", n, f, {constant_start(n, 0.0)});
  p.description = "1-D reaction-diffusion, two species, " + std::to_string(points) + " points";
  return p;
}

TestProblem laplace2d(Index wanted) {
  const Index m = grid_side(wanted, 2);
  const double h = 1.0 / static_cast<double>(m + 1);
  const double c = 1.0 / (h * h);
  auto f = [m, c](const auto& u, auto& out) {
    using T = typename std::decay_t<decltype(u)>::Scalar;
    // kinLaplace_bnd's IJth(u, i, j) = u[(j − 1) + (i − 1) NY], 1-based: here k = j + i m.
    for (Index i = 0; i < m; ++i) {
      for (Index j = 0; j < m; ++j) {
        const Index k = j + i * m;
        T horizontal = -2.0 * u[k], vertical = -2.0 * u[k];
        if (i > 0) horizontal += u[k - m];
        if (i + 1 < m) horizontal += u[k + m];
        if (j > 0) vertical += u[k - 1];
        if (j + 1 < m) vertical += u[k + 1];
        out[k] = c * horizontal + c * vertical + u[k] - u[k] * u[k] * u[k] + 2.0;
      }
    }
  };
  TestProblem p = root_test_problem("laplace2d", m * m, f, {constant_start(m * m, 0.0)});
  p.description = "2-D u'' + u - u^3 + 2 = 0, " + std::to_string(m) + "x" + std::to_string(m) +
                  " grid (SUNDIALS kinLaplace_bnd)";
  return p;
}

std::vector<TestProblem> problems_of_size(Index n) {
  std::vector<TestProblem> out;
  out.push_back(broyden_tridiagonal(n));
  out.push_back(bratu2d(n));
  out.push_back(reaction_diffusion1d(n));
  out.push_back(laplace2d(n));
  return out;
}

}  // namespace

ProblemSetEntry large_problem_set() {
  return {.name = "large",
          .description =
              "sparse systems of run-time size (large:n=K): Broyden tridiagonal, 2-D Bratu "
              "(PETSc ex5), 1-D reaction-diffusion, kinLaplace_bnd (SUNDIALS)",
          .problems =
              [] {
                std::vector<TestProblem> out;
                out.push_back(broyden_tridiagonal(10'000));
                out.push_back(bratu2d(10'000));
                out.push_back(reaction_diffusion1d(10'000));
                out.push_back(laplace2d(31 * 31));  // the example's own grid
                return out;
              },
          .solved_threshold = 1e-8,
          .problems_of_size = problems_of_size,
          .default_solvers = {"newton", "newton:linesearch=1", "newton:linesearch=1,reuse=10",
                              "newton:linesearch=1,linear=gmres,preconditioner=ilu0",
                              "pseudo-transient:growth=1.1", "auto", "anderson",
                              "kinsol:newton-band", "kinsol:newton-klu", "kinsol:newton-spgmr",
                              // PETSc's SNES ex5 form (-snes_fd_color); invalid_input rows in a
                              // build without PETSc
                              "petsc:newtonls"}};
}

}  // namespace nlobs
