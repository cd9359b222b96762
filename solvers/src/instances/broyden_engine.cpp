// Explicit instantiations of BroydenEngine at the library's sizes
// (nlobs/solvers/library_sizes.hpp); the header declares them extern.
#include "nlobs/solvers/broyden_engine.hpp"

namespace nlobs {

#define NLOBS_INSTANTIATE(n) template class BroydenEngine<n>;
NLOBS_FOR_EACH_LIBRARY_SIZE(NLOBS_INSTANTIATE)
#undef NLOBS_INSTANTIATE

}  // namespace nlobs
