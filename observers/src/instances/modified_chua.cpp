// The observers the CLI builds for ModifiedChua, compiled once (their headers declare them extern):
// the MVT observer, the high-gain observer and its Taylor-mode observability maps.
#include "nlobs/observers/high_gain_observer.hpp"
#include "nlobs/observers/mvt_observer.hpp"
#include "nlobs/observers/taylor_observability_map.hpp"

namespace nlobs {

static_assert(3 == (ModifiedChua::kStates > 2 ? ModifiedChua::kStates : 2),
              "catalogue.hpp's lowest order for ModifiedChua must be max(2, n)");

template class MvtObserver<ModifiedChua>;
template class HighGainObserver<ModifiedChua>;
template std::shared_ptr<ObservabilityMap> make_taylor_observability_map<ModifiedChua>(
    const ModifiedChua&, int, std::string);
template class TaylorObservabilityMap<ModifiedChua, 3>;
template class TaylorObservabilityMap<ModifiedChua, 4>;
template class TaylorObservabilityMap<ModifiedChua, 5>;
template class TaylorObservabilityMap<ModifiedChua, 6>;
template class TaylorObservabilityMap<ModifiedChua, 7>;
template class TaylorObservabilityMap<ModifiedChua, 8>;

}  // namespace nlobs
