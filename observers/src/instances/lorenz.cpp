// The observers the CLI builds for Lorenz, compiled once (their headers declare them extern):
// the MVT observer, the high-gain observer and its Taylor-mode observability maps.
#include "nlobs/observers/high_gain_observer.hpp"
#include "nlobs/observers/mvt_observer.hpp"
#include "nlobs/observers/taylor_observability_map.hpp"

namespace nlobs {

static_assert(3 == (Lorenz::kStates > 2 ? Lorenz::kStates : 2),
              "catalogue.hpp's lowest order for Lorenz must be max(2, n)");

template class MvtObserver<Lorenz>;
template class HighGainObserver<Lorenz>;
template std::shared_ptr<ObservabilityMap> make_taylor_observability_map<Lorenz>(const Lorenz&, int,
                                                                                 std::string);
template class TaylorObservabilityMap<Lorenz, 3>;
template class TaylorObservabilityMap<Lorenz, 4>;
template class TaylorObservabilityMap<Lorenz, 5>;
template class TaylorObservabilityMap<Lorenz, 6>;
template class TaylorObservabilityMap<Lorenz, 7>;
template class TaylorObservabilityMap<Lorenz, 8>;

}  // namespace nlobs
