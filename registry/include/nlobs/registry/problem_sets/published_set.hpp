#pragma once
// The built-in set "published": square polynomial systems of the interval-analysis,
// homotopy-continuation and global-optimization benchmark literature, ported from their
// published sources, each with the real roots the source gives or that we verified (every listed
// root refined by Newton in 60-digit arithmetic and rounded to double: ‖F‖₂ ≤ 2e-15 there), the
// published box where the source poses one, and two or three labelled starts (the published
// start where there is one). Engines that take bounds get the box; a point outside it is
// `outside_bounds`.
//   hammarling-2x2 (n = 4), hammarling-3x3 (n = 9): X² = A, A = 1e-4 I + e₁e₂ᵀ, X row by row,
//     from X = I (Burkardt's test_nonlin, problems 15 and 16). 2×2: its only two real square roots
//     ±[[0.01, 50], [0, 0.01]]; 3×3: the primary roots ±(0.01 I + 50 e₁e₂ᵀ), the others form
//     families through singular Jacobians (A is derogatory).
//   katsura (n = 6): Katsura's magnetism problem with N = 5 [Kat90], as PoSSo poses it; all 16
//     real roots of its 32.
//   eco (n = 5 and 8): Morgan's economics problem [Mor87, p. 148]; all real roots (4 and 8) of
//     the 8 and 64 PHCpack lists [Ver99].
//   i1 (n = 10): the interval benchmark i1 on [−2, 2]¹⁰ [HS95, VMK97]; its one root in the box.
//   combustion (n = 10): Morgan's combustion at 3000 K on [0, 1e8]¹⁰ [Mor87, VMB97]; its one
//     root there. Values from 6e−11 to 1.5e−5: the problem states its f_scale.
//   meintjes-morgan (n = 5): hydrocarbon combustion equilibrium [MM90] on [0, 1e8]⁵ [VMB97]; the
//     one root of its four real ones with no negative component.
//   floudas-14.1.2 (n = 5): the same equilibrium as the handbook prints it, with 3 R10 y2² for
//     2 R10 y2² in the second equation, on [1e−4, 100]⁵ [Flo99]; its root in the box.
//   brown-almost-linear (n = 5): Brown's almost-linear system on [−2, 2]⁵, handbook problem 14.1.5
//     [Flo99]; its two roots in the box of three real ones.
//   kin2 (n = 8): inverse position of a 6R manipulator [MS87] on [−1, 1]⁸; its 10 real roots as
//     Numerica lists them [VMD97].
#include "nlobs/registry/problem_sets.hpp"

namespace nlobs {
ProblemSetEntry published_problem_set();
}  // namespace nlobs
