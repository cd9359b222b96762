// The observers the CLI builds for OscillatorNonlinearOutput, compiled once (their headers declare
// them extern): the MVT observer, the high-gain observer and its Taylor-mode observability maps.
#include "nlobs/observers/high_gain_observer.hpp"
#include "nlobs/observers/mvt_observer.hpp"
#include "nlobs/observers/taylor_observability_map.hpp"

namespace nlobs {

static_assert(2 ==
                  (OscillatorNonlinearOutput::kStates > 2 ? OscillatorNonlinearOutput::kStates : 2),
              "catalogue.hpp's lowest order for OscillatorNonlinearOutput must be max(2, n)");

template class MvtObserver<OscillatorNonlinearOutput>;
template class HighGainObserver<OscillatorNonlinearOutput>;
template std::shared_ptr<ObservabilityMap> make_taylor_observability_map<OscillatorNonlinearOutput>(
    const OscillatorNonlinearOutput&, int, std::string);
template class TaylorObservabilityMap<OscillatorNonlinearOutput, 2>;
template class TaylorObservabilityMap<OscillatorNonlinearOutput, 3>;
template class TaylorObservabilityMap<OscillatorNonlinearOutput, 4>;
template class TaylorObservabilityMap<OscillatorNonlinearOutput, 5>;
template class TaylorObservabilityMap<OscillatorNonlinearOutput, 6>;
template class TaylorObservabilityMap<OscillatorNonlinearOutput, 7>;
template class TaylorObservabilityMap<OscillatorNonlinearOutput, 8>;

}  // namespace nlobs
