// The observer the CLI builds for ChaoticNoLinear, compiled once (its header declares it extern).
#include "nlobs/observers/mvt/mvt_observer.hpp"

namespace nlobs {

static_assert(ChaoticNoLinear::kOutputs != 1 || ChaoticNoLinear::kInputs != 0,
              "an autonomous one-output model belongs in catalogue.hpp's high-gain list");

template class MvtObserver<ChaoticNoLinear>;

}  // namespace nlobs
