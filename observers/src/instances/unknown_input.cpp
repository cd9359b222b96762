// The observer the CLI builds for UnknownInputIntegrator, compiled once (its header declares it
// extern).
#include "nlobs/observers/mvt/mvt_observer.hpp"

namespace nlobs {

static_assert(UnknownInputIntegrator::kOutputs != 1 || UnknownInputIntegrator::kInputs != 0,
              "an autonomous one-output model belongs in catalogue.hpp's high-gain list");

template class MvtObserver<UnknownInputIntegrator>;

}  // namespace nlobs
