// The model's registry entry: its parameters (each with its meaning; defaults from the struct),
// sample time and scheme. One registration: its sizes (2 states, 1 output, no input) decide
// which observer types take it.
#include "example_plugin.hpp"
#include "fitzhugh_nagumo.hpp"
#include "nlobs/registry/register_model.hpp"

namespace example {

void add_fitzhugh_nagumo(nlobs::PluginRegistrar& registrar) {
  using Model = FitzHughNagumo;
  registrar.add_model(nlobs::model_entry(nlobs::ModelDefinition<Model>{
      .name = "fitzhugh-nagumo",
      .description = "FitzHugh-Nagumo neuron [FitzHugh 1961], y = x1 (example plugin)",
      .parameters = {{"a", "x2' = eps (x1 + a - b x2)", [](Model& m) -> double& { return m.a; }},
                     {"b", "x2' = eps (x1 + a - b x2)", [](Model& m) -> double& { return m.b; }},
                     {"epsilon", "time-scale ratio eps",
                      [](Model& m) -> double& { return m.epsilon; }},
                     {"current", "x1' = x1 - x1^3/3 - x2 + I",
                      [](Model& m) -> double& { return m.current; }}},
      .default_step = 0.05,
  }));
}

}  // namespace example
