// Explicit instantiations of PseudoTransientEngine at the library's sizes
// (nlobs/solvers/library_sizes.hpp); the header declares them extern.
#include "nlobs/solvers/pseudo_transient_engine.hpp"

namespace nlobs {

#define NLOBS_INSTANTIATE(n) template class PseudoTransientEngine<n>;
NLOBS_FOR_EACH_LIBRARY_SIZE(NLOBS_INSTANTIATE)
#undef NLOBS_INSTANTIATE

}  // namespace nlobs
