// The observers the CLI builds for ModifiedChua, compiled once (their headers declare them extern):
// the MVT observer, the high-gain observer and its Taylor-mode observability maps.
#include "nlobs/observers/high_gain/high_gain_observer.hpp"
#include "nlobs/observers/high_gain/taylor_observability_map.hpp"
#include "nlobs/observers/mvt/mvt_observer.hpp"

namespace nlobs {

#define NLOBS_INSTANTIATE_TAYLOR_MAP(M, N) template class TaylorObservabilityMap<M, N>;

static_assert(3 == (ModifiedChua::kStates > 2 ? ModifiedChua::kStates : 2),
              "catalogue.hpp's lowest order for ModifiedChua must be max(2, n)");

template class MvtObserver<ModifiedChua>;
template class HighGainObserver<ModifiedChua>;
template std::shared_ptr<ObservabilityMap> make_taylor_observability_map<ModifiedChua>(
    const ModifiedChua&, int, std::string);
NLOBS_TAYLOR_ORDERS_FROM(NLOBS_INSTANTIATE_TAYLOR_MAP, ModifiedChua, 3)

}  // namespace nlobs
