#include "nlobs/observers/window/window_estimator.hpp"

namespace nlobs {

std::string_view to_string(WindowGain gain) {
  switch (gain) {
    case WindowGain::kAuto:
      return "auto";
    case WindowGain::kIdentity:
      return "identity";
    case WindowGain::kScalar:
      return "scalar";
    case WindowGain::kNewton:
      return "newton";
  }
  return "unknown";
}

void WindowEstimatorOptions::validate() const {
  if (window < 0) {
    throw InvalidInput("WindowEstimatorOptions::window = " + std::to_string(window) +
                       " must be >= 0 (0 = the square window n/p)");
  }
  if (!std::isfinite(gain_scale) || gain_scale == 0.0) {
    std::ostringstream os;
    os << "WindowEstimatorOptions::gain_scale = " << gain_scale
       << " must be finite and nonzero (Psi = gain_scale I must be invertible)";
    throw InvalidInput(os.str());
  }
  if (measurement_covariance.size()) {
    detail::require_covariance("WindowEstimatorOptions", "measurement_covariance",
                               measurement_covariance, detail::Definiteness::kDefinite);
  }
  if (!(consistency_quantile > 0.0 && consistency_quantile < 1.0)) {
    detail::invalid_option("WindowEstimatorOptions", "consistency_quantile", "be in (0, 1)",
                           detail::option_value(consistency_quantile));
  }
  if (initial_estimate.size() == 0 || !initial_estimate.allFinite()) {
    std::ostringstream os;
    os << "WindowEstimatorOptions::initial_estimate = [" << initial_estimate.transpose()
       << "] must be the model's n states, finite";
    throw InvalidInput(os.str());
  }
}

}  // namespace nlobs
