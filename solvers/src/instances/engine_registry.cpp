// The registry and its built-in entries at the library's sizes (nlobs/solvers/library_sizes.hpp):
// the only place that names every engine, so that engine_registry.hpp names none.
#include "nlobs/solvers/engine_registry.hpp"

#include "nlobs/solvers/builtin_engines.hpp"

namespace nlobs {

#define NLOBS_INSTANTIATE(n)           \
  template class EngineRegistry<n>;    \
  template class DynamicSizeEngine<n>; \
  template void add_builtin_engines<n>(EngineRegistry<n>&);
NLOBS_FOR_EACH_LIBRARY_SIZE(NLOBS_INSTANTIATE)
#undef NLOBS_INSTANTIATE

}  // namespace nlobs
