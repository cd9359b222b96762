#pragma once
// Why a solve ended. Every engine reports exactly one of these.
#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>

#include "nlobs/common/invalid_input.hpp"

namespace nlobs {

enum class Status {
  kConverged,         // an enabled convergence criterion (step, residual, error bound) holds
  kMaxIterations,     // StopCriteria::max_iterations reached
  kMaxEvaluations,    // StopCriteria::max_evaluations reached
  kStagnated,         // the step stopped shrinking and |F| stopped falling (cycling, a floor)
  kRepeatedIterates,  // three consecutive iterates are equal (paper, Remark 8)
  kDiverged,   // the steps grow geometrically while |F| does not fall, or x left divergence_limit
  kNonFinite,  // G (or F) returned inf/NaN; the last finite iterate is returned
  kSingularJacobian,  // Newton: the Jacobian of F is (numerically) singular
  kInvalidInput,      // only from solve_or_report(): bad dimensions, x0 or options
  kSolverFailure,     // a backend (Ceres, NLopt) reported a failure; see Summary::message
  // A bounded solve (Engine::set_bounds) can go no further inside the box: at a point on its
  // boundary the engine's direction — Newton's step, the pseudo-transient flow, or the descent
  // direction −∇½‖F‖² — points out of it (the held component is named in Summary::message).
  // For the descent direction the point is a minimum of ‖F‖ on the boundary: a root in the box,
  // if any, lies elsewhere (another start; `auto`).
  kBlockedByBound,
  // The step is at the level of rounding in x (‖Δx‖∞ ≤ 1e4 · ε · (‖x‖∞ + 1)) and ‖F‖ has stopped
  // falling: the engine can get no closer in double precision (StopCriteria). Usable when ‖F‖
  // meets acceptance_tolerance, like the other statuses that cut a run short.
  kRoundingFloor,
  // `auto`: PolyalgorithmOptions::shared_minimum of its stages (default two; different methods)
  // ended, none usable, at the same point with the same ‖F‖∞ (each within 1e-3, relative), and
  // that point is the best any stage found: a local minimum of ‖F‖ that is not a root, which the
  // later stages are not run to find again. Usable when ‖F‖ meets acceptance_tolerance, like the
  // statuses that cut a run short.
  kLocalMinimum,
  // SolverOptions::iteration_callback returned IterationDecision::kStop: the current iterate is
  // returned. Usable when ‖F‖ meets acceptance_tolerance, like the statuses that cut a run short.
  kStoppedByCallback,
};

// Lowercase snake_case name used in reports and JSON ("converged", "max_iterations", ...).
std::string_view to_string(Status status);

// Bad input (dimension mismatch, non-finite initial guess, invalid options) throws
// InvalidInput (nlobs/common/invalid_input.hpp), the message naming what and its value.

// How user text (an engine spec, a CSV cell) appears in an error message: single-quoted,
// nlobs::printable() (nlobs/common/printable.hpp): cut to max_length bytes ("..." after: a
// hostile megabyte stays one line), control characters and invalid UTF-8 written as \xNN.
inline constexpr std::size_t kExcerptLength = 60;
std::string quoted_excerpt(std::string_view text, std::size_t max_length = kExcerptLength);

}  // namespace nlobs
