// Explicit instantiations of the engine base and the fixed-point engines at the library's
// sizes (nlobs/solvers/library_sizes.hpp); the headers declare them extern.
#include "nlobs/solvers/engine.hpp"

#include "nlobs/solvers/fixed_point_engines.hpp"

namespace nlobs {

#define NLOBS_INSTANTIATE(n)                                 \
  template class Engine<n>;                                  \
  template class AcceleratedEngine<n, PicardStep<n>>;        \
  template class AcceleratedEngine<n, AitkenTransform<n>>;   \
  template class AcceleratedEngine<n, SteffensenRestart<n>>; \
  template class AcceleratedEngine<n, AndersonMixing<n>>;    \
  template class PicardEngine<n>;                            \
  template class AitkenEngine<n>;                            \
  template class SteffensenEngine<n>;                        \
  template class AndersonEngine<n>;
NLOBS_FOR_EACH_LIBRARY_SIZE(NLOBS_INSTANTIATE)
#undef NLOBS_INSTANTIATE

}  // namespace nlobs
