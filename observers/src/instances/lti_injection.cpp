// The observers the CLI builds for LtiOutputInjection, compiled once (their headers declare them
// extern): the MVT observer, the high-gain observer and its Taylor-mode observability maps.
#include "nlobs/observers/high_gain/high_gain_observer.hpp"
#include "nlobs/observers/high_gain/taylor_observability_map.hpp"
#include "nlobs/observers/mvt/mvt_observer.hpp"

namespace nlobs {

#define NLOBS_INSTANTIATE_TAYLOR_MAP(M, N) template class TaylorObservabilityMap<M, N>;

static_assert(2 == (LtiOutputInjection::kStates > 2 ? LtiOutputInjection::kStates : 2),
              "catalogue.hpp's lowest order for LtiOutputInjection must be max(2, n)");

template class MvtObserver<LtiOutputInjection>;
template class HighGainObserver<LtiOutputInjection>;
template std::shared_ptr<ObservabilityMap> make_taylor_observability_map<LtiOutputInjection>(
    const LtiOutputInjection&, int, std::string);
NLOBS_TAYLOR_ORDERS_FROM(NLOBS_INSTANTIATE_TAYLOR_MAP, LtiOutputInjection, 2)

}  // namespace nlobs
