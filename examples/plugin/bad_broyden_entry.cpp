// The engine's registry entry at Dynamic size: every fixed size falls back to it, so one
// registration serves a window of any size and every problem of a set.
#include <memory>

#include "bad_broyden_engine.hpp"
#include "example_plugin.hpp"

namespace example {

void add_bad_broyden(nlobs::PluginRegistrar& registrar) {
  registrar.add_engine(
      {.name = "bad-broyden",
       .description = "Broyden's second (bad) method with backtracking and Jacobian restarts "
                      "(example plugin)",
       // The key names the field it sets; its older, shorter name is an alias.
       .options = {{"max_backtracks",
                    "step halvings before the Jacobian is renewed; default 10",
                    {"backtracks"}}},
       .examples = {"bad-broyden", "bad-broyden:max_backtracks=4"},
       .make = [](nlobs::EngineSpecReader& spec,
                  nlobs::SolverOptions options) -> std::unique_ptr<nlobs::Engine<>> {
         BadBroydenOptions broyden;
         if (auto k = spec.integer("max_backtracks", 0, 60)) broyden.max_backtracks = *k;
         return std::make_unique<BadBroydenEngine<>>(std::move(options), broyden);
       }});
}

}  // namespace example
