// The engine's spec (its description and keys) and its registry entry at Dynamic size:
// every fixed size falls back to it, so one registration serves a window of any size and every
// problem of a set.
#include "bad_broyden_engine.hpp"
#include "example_plugin.hpp"
#include "nlobs/solvers/engine_registry.hpp"

namespace example {

nlobs::EngineDescription BadBroydenOptions::describe() {
  return {"bad-broyden",
          "Broyden's second (bad) method with backtracking and Jacobian restarts (example "
          "plugin)",
          // The key names the field it sets; its older, shorter name is an alias.
          {{"max_backtracks",
            "step halvings before the Jacobian is renewed; default 10",
            {"backtracks"}}},
          {"bad-broyden", "bad-broyden:max_backtracks=4"}};
}

void BadBroydenOptions::read(nlobs::EngineSpecReader& spec) {
  if (auto k = spec.integer("max_backtracks", 0, 60)) max_backtracks = *k;
}

void add_bad_broyden(nlobs::PluginRegistrar& registrar) {
  registrar.add_engine(nlobs::engine_entry<nlobs::Dynamic, BadBroydenEngine<>>());
}

}  // namespace example
