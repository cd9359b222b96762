// ProjectedGaussNewtonOptions' validation (least_squares/projected_gauss_newton.hpp).
#include "nlobs/common/invalid_input.hpp"
#include "nlobs/solvers/least_squares/projected_gauss_newton.hpp"
#include "nlobs/solvers/options_validation.hpp"

namespace nlobs {

void ProjectedGaussNewtonOptions::validate() const {
  constexpr const char* kOwner = "ProjectedGaussNewtonOptions";
  require_option(max_iterations >= 1, kOwner, "max_iterations", static_cast<double>(max_iterations),
                 "must be >= 1");
  require_option(step_tolerance > 0.0, kOwner, "step_tolerance", step_tolerance, "must be > 0");
  require_option(cost_tolerance > 0.0, kOwner, "cost_tolerance", cost_tolerance, "must be > 0");
  line_search.validate();
  if (line_search.kind != LineSearch::Kind::kBacktracking || !line_search.require_descent) {
    throw InvalidInput(
        "ProjectedGaussNewtonOptions::line_search must backtrack with require_descent: the stop "
        "rules take a step that does not lower V for the end of the path");
  }
}

}  // namespace nlobs
