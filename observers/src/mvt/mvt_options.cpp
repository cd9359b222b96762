#include "nlobs/observers/mvt/mvt_options.hpp"

#include "nlobs/observers/core/option_checks.hpp"

namespace nlobs {

void MvtOptions::validate() const {
  detail::require_name("MvtOptions", name);
  detail::require_finite("MvtOptions", "initial_estimate", initial_estimate);
  if (initial_error_estimate.size() != 0) {
    detail::require_finite("MvtOptions", "initial_error_estimate", initial_error_estimate);
  }
  detail::require_positive("MvtOptions", "sample_time", sample_time);
  detail::require_at_least("MvtOptions", "eta", eta, 1.0);
  detail::require_non_negative("MvtOptions", "injection_gain", injection_gain);
  detail::require_at_least("MvtOptions", "substeps", static_cast<long>(substeps), 1L);
  detail::require_positive("MvtOptions", "absolute_tolerance", absolute_tolerance);
  detail::require_positive("MvtOptions", "relative_tolerance", relative_tolerance);
}

}  // namespace nlobs
