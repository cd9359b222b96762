// The observers the CLI builds for PendulumTimeVaryingFriction, compiled once (their headers
// declare them extern): the MVT observer, the high-gain observer and its Taylor-mode observability
// maps.
#include "nlobs/observers/high_gain/high_gain_observer.hpp"
#include "nlobs/observers/high_gain/taylor_observability_map.hpp"
#include "nlobs/observers/mvt/mvt_observer.hpp"

namespace nlobs {

#define NLOBS_INSTANTIATE_TAYLOR_MAP(M, N) template class TaylorObservabilityMap<M, N>;

static_assert(2 == (PendulumTimeVaryingFriction::kStates > 2 ? PendulumTimeVaryingFriction::kStates
                                                             : 2),
              "catalogue.hpp's lowest order for PendulumTimeVaryingFriction must be max(2, n)");

template class MvtObserver<PendulumTimeVaryingFriction>;
template class HighGainObserver<PendulumTimeVaryingFriction>;
template std::shared_ptr<ObservabilityMap>
make_taylor_observability_map<PendulumTimeVaryingFriction>(const PendulumTimeVaryingFriction&, int,
                                                           std::string);
NLOBS_TAYLOR_ORDERS_FROM(NLOBS_INSTANTIATE_TAYLOR_MAP, PendulumTimeVaryingFriction, 2)

}  // namespace nlobs
