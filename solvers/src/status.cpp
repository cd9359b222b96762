#include "nlobs/solvers/status.hpp"

#include <algorithm>

#include "nlobs/common/printable.hpp"

namespace nlobs {

std::string_view to_string(Status status) {
  switch (status) {
    case Status::kConverged:
      return "converged";
    case Status::kMaxIterations:
      return "max_iterations";
    case Status::kMaxEvaluations:
      return "max_evaluations";
    case Status::kStagnated:
      return "stagnated";
    case Status::kRepeatedIterates:
      return "repeated_iterates";
    case Status::kDiverged:
      return "diverged";
    case Status::kNonFinite:
      return "non_finite";
    case Status::kSingularJacobian:
      return "singular_jacobian";
    case Status::kInvalidInput:
      return "invalid_input";
    case Status::kSolverFailure:
      return "solver_failure";
    case Status::kBlockedByBound:
      return "blocked_by_bound";
    case Status::kRoundingFloor:
      return "rounding_floor";
    case Status::kLocalMinimum:
      return "local_minimum";
    case Status::kStoppedByCallback:
      return "stopped_by_callback";
  }
  return "unknown";
}

std::string quoted_excerpt(std::string_view text, std::size_t max_length) {
  // Appended, not `"'" + …`: GCC 12 warns (-Wrestrict) on that form wrongly.
  std::string out = "'";
  out += printable(text, max_length);
  out += '\'';
  return out;
}

}  // namespace nlobs
