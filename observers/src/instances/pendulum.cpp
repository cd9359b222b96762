// The observers the CLI builds for PendulumTimeVaryingFriction, compiled once (their headers
// declare them extern): the MVT observer, the high-gain observer and its Taylor-mode observability
// maps.
#include "nlobs/observers/high_gain_observer.hpp"
#include "nlobs/observers/mvt_observer.hpp"
#include "nlobs/observers/taylor_observability_map.hpp"

namespace nlobs {

static_assert(2 == (PendulumTimeVaryingFriction::kStates > 2 ? PendulumTimeVaryingFriction::kStates
                                                             : 2),
              "catalogue.hpp's lowest order for PendulumTimeVaryingFriction must be max(2, n)");

template class MvtObserver<PendulumTimeVaryingFriction>;
template class HighGainObserver<PendulumTimeVaryingFriction>;
template std::shared_ptr<ObservabilityMap>
make_taylor_observability_map<PendulumTimeVaryingFriction>(const PendulumTimeVaryingFriction&, int,
                                                           std::string);
template class TaylorObservabilityMap<PendulumTimeVaryingFriction, 2>;
template class TaylorObservabilityMap<PendulumTimeVaryingFriction, 3>;
template class TaylorObservabilityMap<PendulumTimeVaryingFriction, 4>;
template class TaylorObservabilityMap<PendulumTimeVaryingFriction, 5>;
template class TaylorObservabilityMap<PendulumTimeVaryingFriction, 6>;
template class TaylorObservabilityMap<PendulumTimeVaryingFriction, 7>;
template class TaylorObservabilityMap<PendulumTimeVaryingFriction, 8>;

}  // namespace nlobs
