#include "nlobs/solvers/stop_criteria.hpp"

#include <cmath>
#include <sstream>

#include "nlobs/solvers/status.hpp"

namespace nlobs {
namespace {

[[noreturn]] void fail(const char* option, double value, const char* requirement) {
  std::ostringstream os;
  os << "StopCriteria::" << option << " = " << value << " is invalid: " << requirement;
  throw InvalidInput(os.str());
}

void require_positive(const char* option, const std::optional<double>& value) {
  if (value && !(std::isfinite(*value) && *value > 0.0)) {
    fail(option, *value, "must be finite and > 0 (unset it to disable the criterion)");
  }
}

}  // namespace

void validate(const StopCriteria& c) {
  require_positive("step_tolerance", c.step_tolerance);
  require_positive("residual_tolerance", c.residual_tolerance);
  require_positive("error_tolerance", c.error_tolerance);
  if (c.lipschitz_constant && !(std::isfinite(*c.lipschitz_constant) &&
                                *c.lipschitz_constant >= 0.0 && *c.lipschitz_constant < 1.0)) {
    fail("lipschitz_constant", *c.lipschitz_constant,
         "must lie in [0, 1): the error bound needs a contraction");
  }
  if (c.stagnation_patience < 0) {
    fail("stagnation_patience", c.stagnation_patience, "must be >= 0 (0 disables it)");
  }
  if (c.progress_window < 0) {
    fail("progress_window", c.progress_window, "must be >= 0 (0 disables it)");
  }
  if (c.residual_window < 0) {
    fail("residual_window", c.residual_window, "must be >= 0 (0 disables it)");
  }
  if (!(std::isfinite(c.residual_window_per_unknown) && c.residual_window_per_unknown >= 0.0)) {
    fail("residual_window_per_unknown", c.residual_window_per_unknown, "must be finite and >= 0");
  }
  if (!(std::isfinite(c.divergence_growth) && c.divergence_growth > 1.0)) {
    fail("divergence_growth", c.divergence_growth, "must be finite and > 1");
  }
  if (!(c.divergence_limit > 0.0)) {
    fail("divergence_limit", c.divergence_limit, "must be > 0 (may be +inf to disable)");
  }
  if (!(std::isfinite(c.acceptance_tolerance) && c.acceptance_tolerance > 0.0)) {
    fail("acceptance_tolerance", c.acceptance_tolerance, "must be finite and > 0");
  }
  if (c.max_iterations < 1) fail("max_iterations", c.max_iterations, "must be >= 1");
  if (c.max_evaluations < 1) fail("max_evaluations", c.max_evaluations, "must be >= 1");
  if (!c.step_tolerance && !c.residual_tolerance && !c.error_tolerance &&
      c.combine == Combine::kAll) {
    throw InvalidInput(
        "StopCriteria::combine = kAll needs at least one convergence criterion "
        "(step_tolerance, residual_tolerance or error_tolerance)");
  }
}

}  // namespace nlobs
