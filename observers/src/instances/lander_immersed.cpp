// The observer the CLI builds for LunarLanderImmersed, compiled once (its header declares it
// extern).
#include "nlobs/observers/mvt/mvt_observer.hpp"

namespace nlobs {

static_assert(LunarLanderImmersed::kOutputs != 1 || LunarLanderImmersed::kInputs != 0,
              "an autonomous one-output model belongs in catalogue.hpp's high-gain list");

template class MvtObserver<LunarLanderImmersed>;

}  // namespace nlobs
