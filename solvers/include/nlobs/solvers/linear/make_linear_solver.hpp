#pragma once
// A linear solver from a spec string, in the engine spec grammar (engine_spec.hpp):
//   dense-lu | band-lu[:lower=L,upper=U] | sparse-lu | klu | umfpack[:ordering=amd|metis]
//   gmres[:restart=30,max_iterations=300,preconditioner=none|jacobi|ilu0|ilut|boomeramg,
//          drop_tolerance=1e-4,fill_factor=10 (ilut),strong_threshold=0.25,cycles=1 (boomeramg)]
//   bicgstab[:max_iterations=300,preconditioner=…,drop_tolerance=…,…]
// Unknown names and options throw InvalidInput listing the valid ones.
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "nlobs/solvers/linear/linear_solver.hpp"

namespace nlobs {

std::unique_ptr<LinearSolver> make_linear_solver(std::string_view spec);

struct SparsityPattern;
// The spec NewtonEngine's sparse path uses for an n-unknown problem whose Jacobian has `pattern`:
// `requested` itself, or for "auto" band-lu when the bandwidth max(lower, upper) is at most
// kAutoBandWidth; else umfpack from kAutoMultifrontalSize unknowns (a wide band fills in, as a
// 2-D or 3-D grid's does, where UMFPACK's dense kernels pay: 2-D Bratu at 3·10⁴ factors in
// 2/3 of KLU's time, at 10⁵ in 1/2), klu below. Throws InvalidInput when the pattern is not n×n.
inline constexpr Index kAutoBandWidth = 16;
inline constexpr Index kAutoMultifrontalSize = 20000;
std::string choose_linear_solver(const std::string& requested, const SparsityPattern& pattern,
                                 Index n);
// The names make_linear_solver accepts, with a one-line description each.
std::vector<std::pair<std::string, std::string>> linear_solver_names();

}  // namespace nlobs
