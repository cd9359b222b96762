// Explicit instantiations of DoglegEngine at the library's sizes (nlobs/solvers/library_sizes.hpp);
// the header declares them extern.
#include "nlobs/solvers/dogleg_engine.hpp"

namespace nlobs {

#define NLOBS_INSTANTIATE(n) template class DoglegEngine<n>;
NLOBS_FOR_EACH_LIBRARY_SIZE(NLOBS_INSTANTIATE)
#undef NLOBS_INSTANTIATE

}  // namespace nlobs
