// A plugin whose registration stages an engine, then throws: nothing of it may be
// registered, and the message names the plugin and the reason.
#include <stdexcept>

#include "nlobs/registry/plugin.hpp"
#include "nlobs/solvers/fixed_point_engines.hpp"

namespace {

void register_throwing(nlobs::PluginRegistrar& r) {
  r.add_engine({.name = "throwing-plugin-engine",
                .description = "staged before the throw",
                .make = [](nlobs::EngineSpecReader&,
                           nlobs::SolverOptions o) -> std::unique_ptr<nlobs::Engine<>> {
                  return std::make_unique<nlobs::PicardEngine<>>(o);
                }});
  throw std::runtime_error("the plugin's configuration file is missing");
}

}  // namespace

NLOBS_PLUGIN(register_throwing)
