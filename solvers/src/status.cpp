#include "nlobs/solvers/status.hpp"

#include <algorithm>

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
  }
  return "unknown";
}

std::string quoted_excerpt(std::string_view text, std::size_t max_length) {
  std::size_t cut = std::min(text.size(), max_length);
  // Never inside a UTF-8 sequence: back up over continuation bytes (10xxxxxx) at the cut.
  while (cut > 0 && cut < text.size() && (static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80) {
    --cut;
  }
  std::string out = "'";
  for (const char c : text.substr(0, cut)) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7f) {
      static const char* const kHex = "0123456789abcdef";
      out += "\\x";
      out += kHex[u >> 4];
      out += kHex[u & 15];
    } else {
      out += c;
    }
  }
  return out + (cut < text.size() ? "...'" : "'");
}

}  // namespace nlobs
