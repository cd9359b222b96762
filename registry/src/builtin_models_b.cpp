// The built-in models, registered as a user's are (register_model.hpp): Van der Pol, the
// oscillator with a nonlinear output, and the MVT paper's two systems.
#include "builtin_models.hpp"
#include "nlobs/models/embedded_forms.hpp"
#include "nlobs/models/systems.hpp"
#include "nlobs/registry/register_model.hpp"

namespace nlobs::detail {

void add_builtin_models_b(ModelRegistry& r) {
  r.add(model_entry(
      ModelDefinition<VanDerPol>{.name = "van-der-pol",
                                 .description = "Van der Pol oscillator, y = x2 ([HG-EMB23])",
                                 .parameters = {{"mu", "x2' = -x1 - mu x2 (x1^2 - 1)",
                                                 [](VanDerPol& m) -> double& { return m.mu; }}}}));
  r.add(model_entry(ModelDefinition<OscillatorNonlinearOutput>{
      .name = "oscillator", .description = "harmonic oscillator, y = x1^2 + x1 ([HG-EMB23])"}));
  r.add(model_entry(ModelDefinition<ChaoticNoLinear>{
      .name = "chaotic",
      .description = "chaotic system without linear term, y = (x1, x2) ([BMH])"}));
  using Robot = FlexibleJointRobot;
  r.add(model_entry(ModelDefinition<Robot>{
      .name = "robot",
      .description = "flexible-joint robot, 1 input, y = (x1, x2, x3) ([BMH])",
      .parameters = {
          {"k1", "joint stiffness over the link inertia",
           [](Robot& m) -> double& { return m.p.k1; }},
          {"damping", "viscous friction", [](Robot& m) -> double& { return m.p.damping; }},
          {"k2", "joint stiffness over the motor inertia",
           [](Robot& m) -> double& { return m.p.k2; }},
          {"gain", "input gain", [](Robot& m) -> double& { return m.p.gain; }},
          {"gravity", "x4' gains -gravity sin x3",
           [](Robot& m) -> double& { return m.p.gravity; }}}}));
}

}  // namespace nlobs::detail
