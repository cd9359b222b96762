#include <cmath>
#include <sstream>
#include <string>

#include "nlobs/observers/core/option_checks.hpp"
#include "nlobs/observers/modulating/modulating_function_observer.hpp"

namespace nlobs {
namespace {

constexpr const char* kWho = "ModulatingOptions";

std::string entries(const Eigen::VectorXd& v) {
  std::ostringstream os;
  os << v.size() << " entries: [";
  for (Eigen::Index i = 0; i < v.size(); ++i) os << (i ? " " : "") << detail::option_value(v[i]);
  os << "]";
  return os.str();
}

}  // namespace

void ModulatingOptions::validate() const {
  detail::require_name(kWho, name);
  detail::require_finite(kWho, "initial_estimate", initial_estimate);
  detail::require_positive(kWho, "sample_time", sample_time);
  detail::require_positive(kWho, "horizon", horizon);
  const std::string of_delta = "sample_time " + detail::option_value(sample_time);
  // T/δ carries the decimal rounding of both: a whole number to 1e-6 relative.
  const double ratio = horizon / sample_time;
  const long intervals = std::lround(ratio);
  if (std::abs(ratio - static_cast<double>(intervals)) > 1e-6 * ratio) {
    detail::invalid_option(kWho, "horizon", "be a multiple of " + of_delta,
                           detail::option_value(horizon));
  }
  const std::string got_intervals = detail::option_value(horizon) + ": " +
                                    std::to_string(intervals) + " interval" +
                                    (intervals == 1 ? "" : "s");
  if (intervals < 4) {
    detail::invalid_option(kWho, "horizon", "span at least 4 intervals of " + of_delta,
                           got_intervals);
  }
  // Composite Simpson pairs the intervals.
  if (quadrature == Quadrature::kSimpson && intervals % 2 != 0) {
    detail::invalid_option(kWho, "horizon",
                           "span an even number of intervals of " + of_delta +
                               " for Simpson quadrature, or use Quadrature::kTrapezoid",
                           got_intervals);
  }
  if (sample_period != 0.0) {
    const double M = sample_period / sample_time;
    // Not finite: M's rounding test passes on inf (inf − inf is NaN), so say it here.
    if (!std::isfinite(sample_period) || !(M >= 1.0 - 1e-9) ||
        std::abs(M - std::round(M)) > 1e-6 * M) {
      detail::invalid_option(kWho, "sample_period",
                             "be 0 (FIR mode) or a positive multiple of " + of_delta,
                             detail::option_value(sample_period));
    }
  }
  // 0 (4 δ) needs no check: T ≥ 4 δ is finite.
  if (resample_max_gap != 0.0 &&
      (!(resample_max_gap >= sample_time) || !std::isfinite(resample_max_gap))) {
    detail::invalid_option(kWho, "resample_max_gap",
                           "be 0 (for 4 sample_time) or finite and >= " + of_delta,
                           detail::option_value(resample_max_gap));
  }
  detail::require_non_negative(kWho, "disturbance_level", disturbance_level);
  if (disturbance_gains.size() != 0 && !disturbance_gains.allFinite()) {
    detail::invalid_option(kWho, "disturbance_gains", "be finite, or empty (no bound)",
                           entries(disturbance_gains));
  }
}

}  // namespace nlobs
