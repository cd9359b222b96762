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

// kinFoodWeb_kry's constants (SUNDIALS examples/kinsol/serial/kinFoodWeb_kry.c): AA, EE, GG, BB,
// DPREY, DPRED, ALPHA; 6 species, 3 prey and 3 predators.
constexpr Index kSpecies = 6, kPrey = 3;
constexpr double kFoodWebAA = 1.0, kFoodWebEE = 1e4, kFoodWebGG = 0.5e-6, kFoodWebBB = 1.0;
constexpr double kFoodWebDPrey = 1.0, kFoodWebDPred = 0.5, kFoodWebAlpha = 1.0;

// kinFoodWeb_kry: 0 = d_i Δc_i + c_i (b_i (1 + α x y) + Σ_j a_ij c_j) on an m × m mesh of the
// unit square, zero normal derivative (a mirrored neighbour outside), species interleaved at
// each point as the example stores them: c[s + 6 (jx + m jy)]. Every operation in the example's
// order (its WebRate's dot product over all six species, its one-sided differences), so that
// KINSOL reproduces the example's published counts on it to the iteration.
TestProblem food_web(Index wanted) {
  const Index m = std::max<Index>(
      2, static_cast<Index>(std::llround(std::sqrt(static_cast<double>(wanted) / kSpecies))));
  const double d = 1.0 / static_cast<double>(m - 1);
  auto f = [m, d](const auto& c, auto& out) {
    using T = typename std::decay_t<decltype(c)>::Scalar;
    for (Index jy = 0; jy < m; ++jy) {
      const double y = d * static_cast<double>(jy);
      const Index down = jy > 0 ? -m : m, up = jy + 1 < m ? m : -m;  // in points
      for (Index jx = 0; jx < m; ++jx) {
        const double x = d * static_cast<double>(jx);
        const Index left = jx > 0 ? -1 : 1, right = jx + 1 < m ? 1 : -1;
        const Index base = kSpecies * (jx + m * jy);
        const double growth = 1.0 + kFoodWebAlpha * x * y;
        for (Index s = 0; s < kSpecies; ++s) {
          const Index k = base + s;
          const bool prey = s < kPrey;
          // Σ_j a_sj c_j, j = 0 … 5: a_ss = −AA; −GG on the predators (prey s), EE on the prey
          // (predator s); 0 elsewhere (its terms add nothing, and are left out).
          T dot = T(0.0);
          for (Index j = 0; j < kSpecies; ++j) {
            if (j == s) {
              dot = dot + c[base + j] * -kFoodWebAA;
            } else if (prey && j >= kPrey) {
              dot = dot + c[base + j] * -kFoodWebGG;
            } else if (!prey && j < kPrey) {
              dot = dot + c[base + j] * kFoodWebEE;
            }
          }
          const T rate = c[k] * ((prey ? kFoodWebBB : -kFoodWebBB) * growth + dot);
          const double diffusion = (prey ? kFoodWebDPrey : kFoodWebDPred) / (d * d);
          const T below = c[k] - c[k + kSpecies * down], above = c[k + kSpecies * up] - c[k];
          const T west = c[k] - c[k + kSpecies * left], east = c[k + kSpecies * right] - c[k];
          out[k] = diffusion * (above - below) + diffusion * (east - west) + rate;
        }
      }
    }
  };
  const Index n = kSpecies * m * m;
  Eigen::VectorXd start(n), scale(n);
  for (Index k = 0; k < n; ++k) {
    const bool prey = k % kSpecies < kPrey;
    start[k] = prey ? 1.0 : 30000.0;
    scale[k] = prey ? 1.0 : 1e-5;
  }
  TestProblem p = root_test_problem("food-web", n, f, {{"x0", start}});
  p.u_scale = scale;  // as the example: sc for both u_scale and f_scale
  p.f_scale = scale;
  p.lower = Eigen::VectorXd::Zero(n);  // KINSetConstraints(2): every concentration > 0
  p.strict_lower = StrictBounds::Constant(n, true);
  p.description = "predator-prey food web, 6 species on a " + std::to_string(m) + "x" +
                  std::to_string(m) + " mesh (SUNDIALS kinFoodWeb_kry)";
  return p;
}

std::vector<TestProblem> problems_of_size(Index n) {
  std::vector<TestProblem> out;
  out.push_back(broyden_tridiagonal(n));
  out.push_back(bratu2d(n));
  out.push_back(reaction_diffusion1d(n));
  out.push_back(laplace2d(n));
  out.push_back(food_web(n));
  return out;
}

}  // namespace

ProblemSetEntry large_problem_set() {
  return {.name = "large",
          .description =
              "sparse systems of run-time size (large:n=K): Broyden tridiagonal, 2-D Bratu "
              "(PETSc ex5), 1-D reaction-diffusion, kinLaplace_bnd and kinFoodWeb_kry (SUNDIALS)",
          .problems =
              [] {
                std::vector<TestProblem> out;
                out.push_back(broyden_tridiagonal(10'000));
                out.push_back(bratu2d(10'000));
                out.push_back(reaction_diffusion1d(10'000));
                out.push_back(laplace2d(31 * 31));   // the example's own grid
                out.push_back(food_web(6 * 8 * 8));  // the example's own 8 x 8 mesh
                return out;
              },
          .solved_threshold = 1e-8,
          .problems_of_size = problems_of_size,
          .default_solvers = {"newton", "newton:linesearch=1", "newton:linesearch=1,reuse=10",
                              "newton:linesearch=1,linear=gmres,preconditioner=ilu0",
                              // hypre's multigrid; invalid_input rows in a build without hypre
                              "newton:linesearch=1,linear=gmres,preconditioner=boomeramg",
                              "pseudo-transient:growth=1.1", "auto", "anderson",
                              "kinsol:newton-band", "kinsol:newton-klu", "kinsol:newton-spgmr",
                              // PETSc's SNES ex5 form (-snes_fd_color), and with the same
                              // BoomerAMG; invalid_input rows in a build without PETSc
                              "petsc:newtonls", "petsc:newtonls:-pc_type=hypre"}};
}

}  // namespace nlobs
