#pragma once
// The compile-time sizes N for which the solvers library compiles the built-in engines and the
// engine registry once (explicit instantiation in src/instances/): a file that uses them at
// these sizes pays for parsing the headers, not for compiling the engines again. An engine
// named in code at any other size is compiled in the file that uses it, as any template; the
// registry's built-in entries at another fixed size are the Dynamic engines adapted
// (DynamicSizeEngine), unless add_builtin_engines<N> gave that size its own.
#include "nlobs/solvers/types.hpp"

// X(n) for each library size; -1 is nlobs::Dynamic.
#define NLOBS_FOR_EACH_LIBRARY_SIZE(X) X(1) X(2) X(3) X(4) X(-1)

namespace nlobs {

static_assert(Dynamic == -1, "NLOBS_FOR_EACH_LIBRARY_SIZE spells Dynamic as -1");

constexpr bool is_library_size(int n) {
#define NLOBS_IS_LIBRARY_SIZE(k) \
  if (n == (k)) return true;
  NLOBS_FOR_EACH_LIBRARY_SIZE(NLOBS_IS_LIBRARY_SIZE)
#undef NLOBS_IS_LIBRARY_SIZE
  return false;
}

}  // namespace nlobs
