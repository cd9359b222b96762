#include "nlobs/observers/mhe/mhe_options.hpp"

#include <sstream>

#include "nlobs/observers/core/option_checks.hpp"
#include "nlobs/solvers/box_bounds.hpp"

namespace nlobs {

void MheOptions::validate() const {
  const char* who = "MheOptions";
  detail::require_name(who, name);
  detail::require_finite(who, "initial_estimate", initial_estimate);
  detail::require_covariance(who, "initial_covariance", initial_covariance,
                             detail::Definiteness::kDefinite);
  detail::require_covariance(who, "process_covariance", process_covariance,
                             detail::Definiteness::kDefinite);
  detail::require_covariance(who, "measurement_covariance", measurement_covariance,
                             detail::Definiteness::kDefinite);
  detail::require_at_least(who, "horizon", horizon, 1L);
  if (horizon > kMaxHorizon) {
    std::ostringstream os;
    os << who << ": horizon = " << horizon << " is above " << kMaxHorizon
       << ", the longest MheEstimator takes (every sample solves the whole horizon, O(N n^3) "
          "per iteration: docs/observers.md)";
    throw InvalidInput(os.str());
  }
  detail::require_at_least(who, "max_iterations", max_iterations, 1L);
  detail::require_positive(who, "step_tolerance", step_tolerance);
  detail::require_positive(who, "cost_tolerance", cost_tolerance);
  detail::validate_box(who, lower_bounds, upper_bounds);
  // The prior must be a point the problem allows (its sizes are the constructor's to check).
  for (Eigen::Index i = 0; i < initial_estimate.size(); ++i) {
    const bool below = i < lower_bounds.size() && initial_estimate[i] < lower_bounds[i];
    const bool above = i < upper_bounds.size() && initial_estimate[i] > upper_bounds[i];
    if (below || above) {
      std::ostringstream os;
      os << who << ": initial_estimate[" << i << "] = " << initial_estimate[i]
         << " lies outside the bounds (" << (below ? "lower" : "upper") << " bound "
         << (below ? lower_bounds[i] : upper_bounds[i]) << ")";
      throw InvalidInput(os.str());
    }
  }
}

}  // namespace nlobs
