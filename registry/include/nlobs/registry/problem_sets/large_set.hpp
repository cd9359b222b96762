#pragma once
// The built-in set "large": sparse systems of run-time size (`nlobs suite large:n=K`,
// `nlobs solve large/NAME:n=K`), each F written generic in its scalar type as a user writes it
// for RootProblem::with_autodiff — nlobs detects the Jacobian's pattern (docs/solvers.md,
// "Sparse Jacobians"). Without :n=K: n ≈ 10⁴, and kinLaplace_bnd's own 31 × 31 grid.
//   broyden-tridiagonal (n = K; start x0 = −1): F_i = (3 − 2x_i) x_i − x_{i−1} − 2x_{i+1} + 1,
//     x_0 = x_{n+1} = 0 [MGH81, problem 30].
//   bratu2d (m × m grid, m = round(√K) ≥ 4, at m = 3 there is no root; start 0): PETSc's SNES ex5
//   with λ = 6, boundary
//     points among the unknowns: F = 4u on the boundary, 4u − Σ interior neighbours − h²λeᵘ
//     inside, h = 1/(m − 1) [PETSc ex5].
//   reaction-diffusion1d (n = 2N, N = ⌊K/2⌋ ≥ 2 points; start 0): two species (u, v)
//     interleaved, −u'' + κ(u³ + u − v) = s, −d v'' + κ(v³ + v − u) = 0 on (0, 1), u = v = 0 at
//     both ends, κ = s = 100, d = 0.1, in the finite-volume form ex5 uses (each equation times
//     h = 1/(N + 1)). Its reaction's Jacobian κ[[3u² + 1, −1], [−1, 3v² + 1]] is positive
//     semi-definite and the diffusion positive definite: one root.
//   laplace2d (m × m interior grid, m = round(√K) ≥ 2, 31 by default; start 0): SUNDIALS'
//     kinLaplace_bnd, ∂²u/∂x² + ∂²u/∂y² + u − u³ + 2 = 0 with u = 0 on the boundary, central
//     differences on h = 1/(m + 1), F as the example writes it (not scaled by h²) and its
//     unknowns in its order (KINSOL solves it with a band Jacobian of widths m).
// The rounding floor of ‖F‖₂ grows with n where F carries 1/h or 1/h² (reaction-diffusion1d,
// laplace2d): near 10⁻⁷ at n = 10⁶, above the set's threshold of 1e-8 (pass --threshold).
#include "nlobs/registry/problem_sets.hpp"

namespace nlobs {
ProblemSetEntry large_problem_set();
}  // namespace nlobs
