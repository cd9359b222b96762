#include "nlobs/observers/baselines/baselines.hpp"

#include <cmath>
#include <sstream>

#include "nlobs/observers/baselines/unscented_kalman_filter.hpp"

namespace nlobs {
namespace {

void require_covariance(const char* who, const char* field, const Eigen::MatrixXd& m) {
  detail::require_covariance(who, field, m, detail::Definiteness::kSemiDefinite);
}

}  // namespace

void LuenbergerOptions::validate() const {
  detail::require_name("LuenbergerOptions", name);
  detail::require_finite("LuenbergerOptions", "initial_estimate", initial_estimate);
  detail::require_finite("LuenbergerOptions", "gain", gain);
}

void SlidingModeOptions::validate() const {
  detail::require_name("SlidingModeOptions", name);
  detail::require_finite("SlidingModeOptions", "initial_estimate", initial_estimate);
  detail::require_finite("SlidingModeOptions", "q", q);
  detail::require_finite("SlidingModeOptions", "r", r);
  detail::require_positive("SlidingModeOptions", "gamma", gamma);
}

void EkfOptions::validate() const {
  detail::require_name("EkfOptions", name);
  detail::require_finite("EkfOptions", "initial_estimate", initial_estimate);
  require_covariance("EkfOptions", "process_covariance", process_covariance);
  require_covariance("EkfOptions", "measurement_covariance", measurement_covariance);
  require_covariance("EkfOptions", "initial_covariance", initial_covariance);
}

void UkfOptions::validate() const {
  detail::require_name("UkfOptions", name);
  detail::require_finite("UkfOptions", "initial_estimate", initial_estimate);
  require_covariance("UkfOptions", "process_covariance", process_covariance);
  require_covariance("UkfOptions", "measurement_covariance", measurement_covariance);
  require_covariance("UkfOptions", "initial_covariance", initial_covariance);
  if (!(alpha > 0.0 && alpha <= 1.0)) {
    detail::invalid_option("UkfOptions", "alpha", "lie in (0, 1]", detail::option_value(alpha));
  }
  detail::require_non_negative("UkfOptions", "beta", beta);
  if (!std::isfinite(kappa)) {
    detail::invalid_option("UkfOptions", "kappa", "be finite", detail::option_value(kappa));
  }
}

}  // namespace nlobs
