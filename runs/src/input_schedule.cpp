#include "nlobs/runs/input_schedule.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>

#include "nlobs/common/invalid_input.hpp"

namespace nlobs {

void InputSchedule::validate(Eigen::Index inputs) const {
  const auto fail = [](const std::string& what) { throw InvalidInput("input schedule: " + what); };
  const auto knots = static_cast<Eigen::Index>(times.size());
  if (knots == 0) fail("it has no knot");
  if (values.rows() != inputs || values.cols() != knots) {
    std::ostringstream os;
    os << "its values are " << values.rows() << " x " << values.cols() << " where the model's "
       << inputs << " input(s) at " << knots << " knot(s) need " << inputs << " x " << knots;
    fail(os.str());
  }
  // The message is built only for the knot that fails (a file may hold a million).
  const auto fail_at = [&](std::size_t i, const auto& say) {
    std::ostringstream os;
    os << std::setprecision(17) << "knot " << i << ": ";
    say(os);
    fail(os.str());
  };
  for (std::size_t i = 0; i < times.size(); ++i) {
    if (!std::isfinite(times[i])) {
      fail_at(i, [&](std::ostream& os) { os << "time " << times[i] << " is not a finite number"; });
    }
    if (i > 0 && !(times[i] > times[i - 1])) {
      fail_at(i, [&](std::ostream& os) {
        os << "time " << times[i] << " does not come after the knot before (" << times[i - 1]
           << "): times must strictly increase";
      });
    }
    if (!values.col(static_cast<Eigen::Index>(i)).allFinite()) {
      fail_at(i, [](std::ostream& os) { os << "a value is not a finite number"; });
    }
  }
}

Eigen::VectorXd InputSchedule::at(double t, double tolerance) const {
  // The first knot after t: u holds the one before it, or moves toward it.
  const auto after = std::upper_bound(times.begin(), times.end(), t + tolerance);
  if (after == times.begin()) return values.col(0);
  if (after == times.end()) return values.col(values.cols() - 1);
  const auto i = static_cast<Eigen::Index>(after - times.begin()) - 1;
  if (interpolation == Interpolation::kPrevious) return values.col(i);
  const double t0 = times[static_cast<std::size_t>(i)], t1 = *after;
  // Halves: t1 − t0 of knots at ∓1e308 would overflow to inf (and the line stay flat).
  const double w = std::clamp((t / 2 - t0 / 2) / (t1 / 2 - t0 / 2), 0.0, 1.0);
  return (1.0 - w) * values.col(i) + w * values.col(i + 1);
}

}  // namespace nlobs
