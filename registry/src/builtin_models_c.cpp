// The built-in models, registered as a user's are (register_model.hpp): the PI paper's lander
// and unknown-input integrator, the modulating-function paper's two systems (their canonical
// forms: nlobs/models/modulating_forms.hpp), the batch reactor of the MHE literature, and the
// reaction–diffusion chain of run-time size.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "builtin_models.hpp"
#include "nlobs/models/modulating_forms.hpp"
#include "nlobs/models/reaction_diffusion_chain.hpp"
#include "nlobs/models/systems.hpp"
#include "nlobs/registry/register_model.hpp"

namespace nlobs::detail {

namespace {
// The chain's sizes arrive as JSON numbers: whole numbers in range, or refused by name. A
// scenario's observers hold n × n covariances, so a million cells is already far past use;
// the cap keeps a hostile file from asking for gigabytes.
struct ChainValues {
  double cells = 200.0, sensors = 4.0, coupling = 1.0, growth = 1.0, threshold = 0.25;
};
constexpr double kMostCells = 1e6, kMostSensors = 1e4;
long whole_number(const char* key, double value, double lowest, double highest,
                  const char* why = "") {
  if (!(value >= lowest && value <= highest) || value != std::floor(value)) {
    std::ostringstream os;
    os << "parameter '" << key << "' of model 'reaction-diffusion' = " << value
       << " must be a whole number in [" << lowest << ", " << highest << "]" << why;
    throw InvalidInput(os.str());
  }
  return static_cast<long>(value);
}

void add_reaction_diffusion(ModelRegistry& r) {
  r.add(model_entry(ModelDefinition<ReactionDiffusionChain, ChainValues>{
      .name = "reaction-diffusion",
      .description = "Nagumo chain of n cells, x' = D dxx + rho x(1-x)(x-a), p point sensors "
                     "([Kee87]); n states at run time",
      .parameters = {{"cells", "n, the states", [](ChainValues& v) -> double& { return v.cells; }},
                     {"sensors", "p, outputs y_j = x at cell floor((j + 1/2) n / p)",
                      [](ChainValues& v) -> double& { return v.sensors; }},
                     {"coupling", "D >= 0", [](ChainValues& v) -> double& { return v.coupling; }},
                     {"growth", "rho >= 0", [](ChainValues& v) -> double& { return v.growth; }},
                     {"threshold", "a in (0, 1)",
                      [](ChainValues& v) -> double& { return v.threshold; }}},
      .default_step = 0.1,
      .build = [](const ChainValues& v) {
        const long cells = whole_number("cells", v.cells, 2.0, kMostCells);
        const std::string why = " (cells = " + std::to_string(cells) + ")";
        return ReactionDiffusionChain(
            {.cells = cells,
             .sensors = whole_number("sensors", v.sensors, 1.0, std::min(v.cells, kMostSensors),
                                     why.c_str()),
             .coupling = v.coupling,
             .growth = v.growth,
             .threshold = v.threshold});
      }}));
}
}  // namespace

void add_builtin_models_c(ModelRegistry& r) {
  using Lander = LunarLander;
  r.add(model_entry(ModelDefinition<Lander>{
      .name = "lander",
      .description = "lunar lander, 1 input, y = x1, domain x3 > 0 ([FFMG19])",
      .parameters = {{"g", "gravity", [](Lander& m) -> double& { return m.p.g; }},
                     {"sigma", "x3' = -sigma u - f",
                      [](Lander& m) -> double& { return m.p.sigma; }},
                     {"alpha", "x2' = g - sigma alpha u / x3",
                      [](Lander& m) -> double& { return m.p.alpha; }}},
      .default_step = 0.001}));
  using Immersed = LunarLanderImmersed;
  r.add(model_entry(ModelDefinition<Immersed>{
      .name = "lander-f",
      .description =
          "lunar lander with f = exp(c sin t) as state x4, y = x1, domain x3 > 0 ([FFMG19])",
      .parameters =
          {{"g", "gravity", [](Immersed& m) -> double& { return m.p.g; }},
           {"sigma", "x3' = -sigma u - x4", [](Immersed& m) -> double& { return m.p.sigma; }},
           {"alpha", "x2' = g - sigma alpha u / x3",
            [](Immersed& m) -> double& { return m.p.alpha; }},
           {"c", "f = exp(c sin t); 0: f constant", [](Immersed& m) -> double& { return m.c; }}},
      .default_step = 0.001}));
  using Integrator = UnknownInputIntegrator;
  r.add(model_entry(ModelDefinition<Integrator>{
      .name = "unknown-input",
      .description = "x' = u + f, f = A sin(omega t) as state x2, y = x1 ([FFMG19], example 3)",
      .parameters = {{"amplitude", "A; 0: f constant",
                      [](Integrator& m) -> double& { return m.amplitude; }},
                     {"omega", "omega (rad/s)", [](Integrator& m) -> double& { return m.omega; }}},
      .default_step = 0.001}));
  using Lti = LtiOutputInjection;
  r.add(model_entry(ModelDefinition<Lti>{
      .name = "lti-injection",
      .description = "x1'=x2, x2'=-a0 x1-a1 x2+gain sin(y), y = x1 ([MF-LTV])",
      .parameters = {
          {"a0", "stiffness", [](Lti& m) -> double& { return m.p.a0; }},
          {"a1", "damping", [](Lti& m) -> double& { return m.p.a1; }},
          {"gain", "output injection gain", [](Lti& m) -> double& { return m.p.gain; }}}}));
  using Pendulum = PendulumTimeVaryingFriction;
  r.add(model_entry(ModelDefinition<Pendulum>{
      .name = "pendulum",
      .description = "pendulum with time-varying friction, y = angle ([MF-LTV])",
      .parameters =
          {{"g", "gravity", [](Pendulum& m) -> double& { return m.p.g; }},
           {"length", "l > 0", [](Pendulum& m) -> double& { return m.p.length; }},
           {"c0", "friction c(t) = c0 + c1 sin(omega_c t)",
            [](Pendulum& m) -> double& { return m.p.c0; }},
           {"c1", "friction's oscillation", [](Pendulum& m) -> double& { return m.p.c1; }},
           {"omega_c", "friction's frequency", [](Pendulum& m) -> double& { return m.p.omega_c; }},
           {"a_max", "unknown acceleration a(t) = a_max sin(omega_a t)",
            [](Pendulum& m) -> double& { return m.p.a_max; }},
           {"omega_a", "acceleration's frequency",
            [](Pendulum& m) -> double& { return m.p.omega_a; }}},
      .build = [](const Pendulum& m) {
        if (!(m.p.length > 0.0)) throw std::invalid_argument("'length' must be > 0");
        return m;
      }}));
  r.add(model_entry(ModelDefinition<BatchReactor>{
      .name = "batch-reactor",
      .description = "A <-> B + C, 2B <-> C; y = RT (cA + cB + cC) ([HR05]); RK4 T = 0.25",
      .parameters = {{"k1", "A -> B + C", [](BatchReactor& m) -> double& { return m.p.k1; }},
                     {"k2", "B + C -> A", [](BatchReactor& m) -> double& { return m.p.k2; }},
                     {"k3", "2B -> C", [](BatchReactor& m) -> double& { return m.p.k3; }},
                     {"k4", "C -> 2B", [](BatchReactor& m) -> double& { return m.p.k4; }},
                     {"rt", "RT, y = RT (cA + cB + cC)",
                      [](BatchReactor& m) -> double& { return m.p.rt; }}},
      .default_step = 0.25}));
  add_reaction_diffusion(r);
}

}  // namespace nlobs::detail
