// The catalogue's observers of one state size, compiled once (instantiate_*.hpp): one unit per
// state size (two for the larger groups), because the models of one size share most of what
// their observers instantiate (the Taylor maps' fixed-size orders, the high-gain and MVT
// machinery). observers/CMakeLists.txt gives the measurement.
#include "instantiate_high_gain.hpp"

namespace nlobs {

NLOBS_INSTANTIATE_HIGH_GAIN_MODEL(Duffing, 2)
NLOBS_INSTANTIATE_HIGH_GAIN_MODEL(VanDerPol, 2)
NLOBS_INSTANTIATE_HIGH_GAIN_MODEL(OscillatorNonlinearOutput, 2)

}  // namespace nlobs
