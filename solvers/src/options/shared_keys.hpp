#pragma once
// The spec keys several engines share (finite_difference, linear_solver, preconditioner,
// ordering) and their reading: written once, for the engines' own read() (private to the
// solvers library).
#include <optional>
#include <string>

#include "nlobs/solvers/engine_spec.hpp"
#include "nlobs/solvers/finite_difference.hpp"

namespace nlobs::detail {

EngineOptionInfo finite_difference_key();
EngineOptionInfo linear_solver_key();  // newton's and pseudo-transient's list
EngineOptionInfo preconditioner_key();
EngineOptionInfo ordering_key();

// finite_difference=forward|central (alias fd), when given.
std::optional<FiniteDifference> read_finite_difference(EngineSpecReader& spec);

// linear_solver=…, preconditioner=… and ordering=… read into one make_linear_solver spec over
// `linear` (the engine's current choice); nullopt when the spec gives none of them. A
// preconditioner without gmres|bicgstab, or an ordering without umfpack, is refused naming
// `engine`.
std::optional<std::string> read_linear_solver(const char* engine, EngineSpecReader& spec,
                                              std::string linear);

}  // namespace nlobs::detail
