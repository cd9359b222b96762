// The engines that take bounds or scaling, for the refusals of Engine::set_bounds and
// Engine::set_scaling: read from the registry, so that they follow it.
#include "nlobs/solvers/engine_registry.hpp"

namespace nlobs {

namespace detail {

// Read from the engines themselves (each engine of the Dynamic registry, every size's fallback,
// made with its default options), so that the list follows the registry, a user's and a plugin's
// engines included. Only on the path of a refusal: it runs every factory.
namespace {

// The registered engines (at Dynamic) of which `takes` holds, each made with its defaults.
template <typename Takes>
std::string engines_that(Takes takes) {
  // A factory that itself sets a refused box would come back here: answer without the list.
  thread_local bool listing = false;
  if (listing) return "(see nlobs list engines)";
  listing = true;
  struct Reset {
    bool& flag;
    ~Reset() { flag = false; }
  } reset{listing};
  std::string list;
  for (const auto& entry : EngineRegistry<Dynamic>::global().entries()) {
    try {
      const auto engine = EngineRegistry<Dynamic>::global().create(entry.name);
      if (engine && takes(*engine)) list += (list.empty() ? "" : ", ") + entry.name;
    } catch (...) {  // an engine that cannot be made with its defaults is not listed
    }
  }
  return list.empty() ? "(none registered)" : list;
}

}  // namespace

std::string engines_taking_bounds(bool strict) {
  return engines_that([strict](const Engine<Dynamic>& engine) {
    return strict ? engine.accepts_strict_bounds() : engine.accepts_bounds();
  });
}

std::string engines_taking_scaling() {
  return engines_that([](const Engine<Dynamic>& engine) { return engine.accepts_scaling(); });
}

}  // namespace detail

}  // namespace nlobs
