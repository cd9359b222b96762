// The observers the CLI builds for Duffing, compiled once (their headers declare them extern):
// the MVT observer, the high-gain observer and its Taylor-mode observability maps.
#include "nlobs/observers/high_gain/high_gain_observer.hpp"
#include "nlobs/observers/high_gain/taylor_observability_map.hpp"
#include "nlobs/observers/mvt/mvt_observer.hpp"

namespace nlobs {

#define NLOBS_INSTANTIATE_TAYLOR_MAP(M, N) template class TaylorObservabilityMap<M, N>;

static_assert(2 == (Duffing::kStates > 2 ? Duffing::kStates : 2),
              "catalogue.hpp's lowest order for Duffing must be max(2, n)");

template class MvtObserver<Duffing>;
template class HighGainObserver<Duffing>;
template std::shared_ptr<ObservabilityMap> make_taylor_observability_map<Duffing>(const Duffing&,
                                                                                  int, std::string);
NLOBS_TAYLOR_ORDERS_FROM(NLOBS_INSTANTIATE_TAYLOR_MAP, Duffing, 2)

}  // namespace nlobs
