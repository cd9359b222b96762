// BoomerAmgOptions' check, the same with or without hypre (boomeramg.hpp).
#include "nlobs/solvers/linear/boomeramg.hpp"
#include "nlobs/solvers/options_validation.hpp"

namespace nlobs {

void BoomerAmgOptions::validate() const {
  require_option(strong_threshold > 0.0 && strong_threshold < 1.0, "BoomerAmgOptions",
                 "strong_threshold", strong_threshold, "must lie in (0, 1)");
  require_option(cycles >= 1 && cycles <= 100, "BoomerAmgOptions", "cycles", cycles,
                 "must lie in [1, 100]");
}

}  // namespace nlobs
