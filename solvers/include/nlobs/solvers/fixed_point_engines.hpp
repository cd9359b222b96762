#pragma once
// The fixed-point engines by name: one loop (AcceleratedEngine), four accelerators.
#include "nlobs/solvers/accelerated_engine.hpp"
#include "nlobs/solvers/accelerators/aitken.hpp"
#include "nlobs/solvers/accelerators/anderson.hpp"
#include "nlobs/solvers/accelerators/picard_step.hpp"
#include "nlobs/solvers/accelerators/steffensen.hpp"
#include "nlobs/solvers/engine_spec.hpp"
#include "nlobs/solvers/library_sizes.hpp"

namespace nlobs {

// x ← G(x).
template <int N = Dynamic>
class PicardEngine : public AcceleratedEngine<N, PicardStep<N>> {
 public:
  explicit PicardEngine(SolverOptions options = {})
      : AcceleratedEngine<N, PicardStep<N>>(std::move(options)) {}
  // The engine as the registry lists it (no options of its own).
  static EngineDescription describe() { return {"picard", "x <- G(x)", {}, {"picard"}}; }
};

// Component-wise Δ² transform of the Picard sequence.
template <int N = Dynamic>
class AitkenEngine : public AcceleratedEngine<N, AitkenTransform<N>> {
 public:
  explicit AitkenEngine(SolverOptions options = {})
      : AcceleratedEngine<N, AitkenTransform<N>>(std::move(options)) {}
  // The engine as the registry lists it (no options of its own).
  static EngineDescription describe() {
    return {"aitken", "component-wise Aitken delta^2 of the Picard sequence", {}, {"aitken"}};
  }
};

// Aitken restarted every three iterates.
template <int N = Dynamic>
class SteffensenEngine : public AcceleratedEngine<N, SteffensenRestart<N>> {
 public:
  explicit SteffensenEngine(SolverOptions options = {})
      : AcceleratedEngine<N, SteffensenRestart<N>>(std::move(options)) {}
  // The engine as the registry lists it (no options of its own).
  static EngineDescription describe() {
    return {"steffensen", "Aitken restarted every three iterates", {}, {"steffensen"}};
  }
};

// Anderson mixing of depth m with damping β.
template <int N = Dynamic>
class AndersonEngine : public AcceleratedEngine<N, AndersonMixing<N>> {
 public:
  using Options = AndersonOptions;

  explicit AndersonEngine(AndersonOptions anderson = {}, SolverOptions options = {})
      : AcceleratedEngine<N, AndersonMixing<N>>(std::move(options), AndersonMixing<N>(anderson)) {}
};

// Compiled once in the library for its sizes (nlobs/solvers/library_sizes.hpp).
#define NLOBS_EXTERN_FIXED_POINT_ENGINES(n)                         \
  extern template class AcceleratedEngine<n, PicardStep<n>>;        \
  extern template class AcceleratedEngine<n, AitkenTransform<n>>;   \
  extern template class AcceleratedEngine<n, SteffensenRestart<n>>; \
  extern template class AcceleratedEngine<n, AndersonMixing<n>>;    \
  extern template class PicardEngine<n>;                            \
  extern template class AitkenEngine<n>;                            \
  extern template class SteffensenEngine<n>;                        \
  extern template class AndersonEngine<n>;
NLOBS_FOR_EACH_LIBRARY_SIZE(NLOBS_EXTERN_FIXED_POINT_ENGINES)
#undef NLOBS_EXTERN_FIXED_POINT_ENGINES

}  // namespace nlobs
