// The observers the CLI builds for VanDerPol, compiled once (their headers declare them extern):
// the MVT observer, the high-gain observer and its Taylor-mode observability maps.
#include "nlobs/observers/high_gain_observer.hpp"
#include "nlobs/observers/mvt_observer.hpp"
#include "nlobs/observers/taylor_observability_map.hpp"

namespace nlobs {

static_assert(2 == (VanDerPol::kStates > 2 ? VanDerPol::kStates : 2),
              "catalogue.hpp's lowest order for VanDerPol must be max(2, n)");

template class MvtObserver<VanDerPol>;
template class HighGainObserver<VanDerPol>;
template std::shared_ptr<ObservabilityMap> make_taylor_observability_map<VanDerPol>(
    const VanDerPol&, int, std::string);
template class TaylorObservabilityMap<VanDerPol, 2>;
template class TaylorObservabilityMap<VanDerPol, 3>;
template class TaylorObservabilityMap<VanDerPol, 4>;
template class TaylorObservabilityMap<VanDerPol, 5>;
template class TaylorObservabilityMap<VanDerPol, 6>;
template class TaylorObservabilityMap<VanDerPol, 7>;
template class TaylorObservabilityMap<VanDerPol, 8>;

}  // namespace nlobs
