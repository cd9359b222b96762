// DoglegOptions: validation, description and spec reading (dogleg_engine.hpp).
#include <cmath>

#include "nlobs/solvers/dogleg_engine.hpp"
#include "nlobs/solvers/options_validation.hpp"
#include "shared_keys.hpp"

namespace nlobs {

void DoglegOptions::validate() const {
  require_option(initial_radius_factor > 0.0 && std::isfinite(initial_radius_factor),
                 "DoglegOptions", "initial_radius_factor", initial_radius_factor,
                 "must be finite and > 0");
}

EngineDescription DoglegOptions::describe() {
  return {"dogleg",
          "Powell's hybrid method (MINPACK hybrj): trust region, dogleg steps, Broyden updates",
          {{"scaling",
            "none|jacobian: trust-region scaling D = I or Jacobian column norms "
            "(MINPACK mode 2|1); default none",
            {"scale"}},
           {"initial_radius_factor", "initial radius factor * |D x0|; default 100", {"factor"}},
           {"broyden_updates", "0/1 Broyden updates between Jacobians; default 1", {"broyden"}},
           detail::finite_difference_key()},
          {"dogleg", "dogleg:scaling=jacobian"}};
}

void DoglegOptions::read(EngineSpecReader& spec) {
  if (auto v = spec.choice("scaling", {"none", "jacobian"})) {
    scaling = *v == "none" ? Scaling::kNone : Scaling::kJacobianColumns;
  }
  if (auto v = spec.number("initial_radius_factor")) initial_radius_factor = *v;
  if (auto v = spec.boolean("broyden_updates")) broyden_updates = *v;
  if (auto v = detail::read_finite_difference(spec)) finite_difference = *v;
}

}  // namespace nlobs
