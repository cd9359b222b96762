// A plugin that stages a problem set of a free name and an engine under a built-in's name
// (newton): the host refuses the whole plugin, naming both sources, and registers neither.
#include "nlobs/registry/plugin.hpp"
#include "nlobs/solvers/fixed_point_engines.hpp"

namespace {

void register_conflicting(nlobs::PluginRegistrar& r) {
  r.add_problem_set({.name = "conflicting-plugin-set",
                     .description = "staged beside a taken engine name",
                     .problems = [] { return std::vector<nlobs::TestProblem>{}; }});
  r.add_engine({.name = "newton",
                .description = "a second newton",
                .make = [](nlobs::EngineSpecReader&,
                           nlobs::SolverOptions o) -> std::unique_ptr<nlobs::Engine<>> {
                  return std::make_unique<nlobs::PicardEngine<>>(o);
                }});
}

}  // namespace

NLOBS_PLUGIN(register_conflicting)
