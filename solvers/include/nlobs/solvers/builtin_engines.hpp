#pragma once
// The built-in engines' registry entries. The library compiles add_builtin_engines<N> for its
// sizes (library_sizes.hpp) and EngineRegistry<N>::global() calls it there; include this
// header only to give the built-in engines fixed-size entries at another size N:
//   nlobs::add_builtin_engines<6>(nlobs::EngineRegistry<6>::global());
// (it compiles every engine at that size in the including file).
//
// Each engine owns its entry (engine_entry, engine_registry.hpp): its options type describes it,
// reads its spec and validates itself (NewtonOptions::describe/read/validate, in src/options/).
// Adding a built-in engine is its header (with its extern declarations at the library sizes),
// its source, one line below and one in src/instances/engines_at_size.inc (its instantiation).
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "nlobs/solvers/broyden_engine.hpp"
#include "nlobs/solvers/ceres_engine.hpp"
#include "nlobs/solvers/dogleg_engine.hpp"
#include "nlobs/solvers/engine_registry.hpp"
#include "nlobs/solvers/fixed_point_engines.hpp"
#include "nlobs/solvers/levenberg_marquardt_engine.hpp"
#include "nlobs/solvers/newton_engine.hpp"
#include "nlobs/solvers/nlopt_engine.hpp"
#include "nlobs/solvers/polyalgorithm_engine.hpp"
#include "nlobs/solvers/pseudo_transient_engine.hpp"

namespace nlobs {

namespace detail {

// `auto`: PolyalgorithmOptions from the spec, and its stages by name from the process-wide
// registry (a user's engines included), in the spec's order (kAutoOrder by default).
template <int N>
typename EngineRegistry<N>::Entry auto_entry() {
  EngineDescription d = PolyalgorithmOptions::describe();
  return {std::move(d.name), std::move(d.description), std::move(d.options), std::move(d.examples),
          [](EngineSpecReader& spec, SolverOptions solver) {
            PolyalgorithmOptions options;
            options.read(spec);
            const std::string order = spec.text("order").value_or(kAutoOrder);
            std::vector<std::unique_ptr<Engine<N>>> stages;
            for (std::size_t at = 0; at <= order.size();) {
              const std::size_t slash = std::min(order.find('/', at), order.size());
              const std::string stage = order.substr(at, slash - at);
              if (stage.empty() || parse_engine_spec(stage).name == "auto") {
                throw InvalidInput("auto: order=" + quoted_excerpt(order) +
                                   " needs engine names other than auto, separated by '/'");
              }
              stages.push_back(EngineRegistry<N>::global().create(stage, solver));
              at = slash + 1;
            }
            return std::make_unique<PolyalgorithmEngine<N>>(std::move(stages), options,
                                                            std::move(solver));
          }};
}

}  // namespace detail

template <int N>
void add_builtin_engines(EngineRegistry<N>& registry) {
  // Idempotent: a name the registry already has an entry of (a second call, or the user's own
  // entry under a built-in's name) is left as it is.
  const auto add = [&registry](typename EngineRegistry<N>::Entry entry) {
    if (!registry.has_entry(entry.name)) registry.add(std::move(entry));
  };
  add(engine_entry<N, PicardEngine<N>>());
  add(engine_entry<N, AitkenEngine<N>>());
  add(engine_entry<N, SteffensenEngine<N>>());
  add(engine_entry<N, AndersonEngine<N>>());
  add(engine_entry<N, NewtonEngine<N>>());
  add(engine_entry<N, DoglegEngine<N>>());
  add(engine_entry<N, BroydenEngine<N>>());
  add(engine_entry<N, LevenbergMarquardtEngine<N>>());
  add(engine_entry<N, PseudoTransientEngine<N>>());
  add(detail::auto_entry<N>());
  add(engine_entry<N, CeresEngine<N>>());
  add(engine_entry<N, NloptEngine<N>>());
}

}  // namespace nlobs
