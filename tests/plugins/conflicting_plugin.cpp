// A plugin that stages an engine of a free name and a problem set under a built-in's name
// (mgh): the host refuses the whole plugin, naming both sources, and registers neither — the
// engine although engines are committed before problem sets.
#include "nlobs/registry/plugin.hpp"
#include "nlobs/solvers/fixed_point_engines.hpp"

namespace {

void register_conflicting(nlobs::PluginRegistrar& r) {
  r.add_engine({.name = "conflicting-plugin-engine",
                .description = "staged beside a taken problem-set name",
                .make = [](nlobs::EngineSpecReader&,
                           nlobs::SolverOptions o) -> std::unique_ptr<nlobs::Engine<>> {
                  return std::make_unique<nlobs::PicardEngine<>>(o);
                }});
  r.add_problem_set({.name = "mgh", .description = "a second mgh", .problems = [] {
                       return std::vector<nlobs::TestProblem>{};
                     }});
}

}  // namespace

NLOBS_PLUGIN(register_conflicting)
