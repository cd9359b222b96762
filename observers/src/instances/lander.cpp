// The observer the CLI builds for LunarLander, compiled once (its header declares it extern).
#include "nlobs/observers/mvt/mvt_observer.hpp"

namespace nlobs {

static_assert(LunarLander::kOutputs != 1 || LunarLander::kInputs != 0,
              "an autonomous one-output model belongs in catalogue.hpp's high-gain list");

template class MvtObserver<LunarLander>;

}  // namespace nlobs
