#pragma once
// The built-in set "bounded": square systems from the literature posed on a box, each with its
// published solution — the engines that take bounds (Engine::set_bounds) get the box; the others
// run unbounded and are judged the same way (a point outside the box is `outside_bounds`).
//   ferraris-tronconi (n = 2): [FT86] (Floudas et al.'s handbook, problem 14.1.4):
//     0.5 sin(x1 x2) − x2/(4π) − x1/2 = 0,
//     (1 − 1/(4π))(e^{2 x1} − e) + e x2/π − 2e x1 = 0, on [0.25, 1] × [1.5, 2π]; two roots in the
//     box, (0.29945, 2.83693) and (0.5, π).
//   bullard-biegler (n = 2): Powell's badly scaled function with 1.001 [BB91]:
//     10⁴ x1 x2 − 1 = 0, e^{−x1} + e^{−x2} − 1.001 = 0, on [5.49e−6, 4.553] × [2.196e−3, 18.21];
//     root (1.450e−5, 6.8933353).
//   shacham-cstr (n = 1): conversion in an isothermal CSTR [Sha86]:
//     x/(1 − x) − 5 ln(0.4(1 − x)/(0.4 − 0.5x)) + 4.45977 = 0 on [0, 0.8), a strict upper
//     bound: F is undefined from 0.8 on (−inf at 0.8, NaN in (0.8, 1)); root 0.757396.
#include "nlobs/registry/problem_sets.hpp"

namespace nlobs {
ProblemSetEntry bounded_problem_set();
}  // namespace nlobs
