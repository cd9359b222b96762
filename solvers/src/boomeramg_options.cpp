// BoomerAmgOptions' check, the same with or without hypre (boomeramg.hpp).
#include <string>

#include "nlobs/common/invalid_input.hpp"
#include "nlobs/solvers/linear/boomeramg.hpp"

namespace nlobs {

void BoomerAmgOptions::validate() const {
  if (!(strong_threshold > 0.0 && strong_threshold < 1.0)) {
    throw InvalidInput("BoomerAmgOptions::strong_threshold = " + std::to_string(strong_threshold) +
                       " must lie in (0, 1)");
  }
  if (cycles < 1 || cycles > 100) {
    throw InvalidInput("BoomerAmgOptions::cycles = " + std::to_string(cycles) +
                       " must lie in [1, 100]");
  }
}

}  // namespace nlobs
