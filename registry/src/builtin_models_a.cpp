// The built-in models, registered as a user's are (register_model.hpp): the Chua systems,
// Lorenz and Duffing. The observers they get are compiled once in the observers library
// (observers/src/instances/), declared extern in their headers.
#include "builtin_models.hpp"
#include "nlobs/models/embedded_forms.hpp"
#include "nlobs/models/modified_chua.hpp"
#include "nlobs/models/systems.hpp"
#include "nlobs/registry/register_model.hpp"

namespace nlobs::detail {

void add_builtin_models_a(ModelRegistry& r) {
  using P = ModifiedChuaParameters;
  r.add(model_entry(ModelDefinition<ModifiedChua, P>{
      .name = "modified-chua",
      .description = "modified Chua attractor, y = x1 ([MGFF23]); Euler T = 0.05",
      .parameters = {{"alpha", "x1' = alpha (x2 + b sin(pi x1 / (2a) + d))",
                      [](P& p) -> double& { return p.alpha; }},
                     {"beta", "x3' = -beta x2", [](P& p) -> double& { return p.beta; }},
                     {"a", "half-period of the sine (!= 0)", [](P& p) -> double& { return p.a; }},
                     {"b", "amplitude of the sine", [](P& p) -> double& { return p.b; }},
                     {"d", "phase of the sine", [](P& p) -> double& { return p.d; }}},
      .default_step = 0.05,
      .default_scheme = Scheme::kEuler,
      .build = [](const P& p) { return ModifiedChua(p); }}));
  r.add(model_entry(ModelDefinition<CubicChua>{
      .name = "cubic-chua",
      .description = "Chua circuit with cubic nonlinearity, y = x2 ([FFMG19])",
      .parameters = {
          {"a", "x1' = a (x2 - x1 - m0 x1 - m1 x1^3)",
           [](CubicChua& m) -> double& { return m.p.a; }},
          {"b", "x3' = -b x2", [](CubicChua& m) -> double& { return m.p.b; }},
          {"m0", "linear slope", [](CubicChua& m) -> double& { return m.p.m0; }},
          {"m1", "cubic coefficient", [](CubicChua& m) -> double& { return m.p.m1; }}}}));
  r.add(model_entry(ModelDefinition<Lorenz>{
      .name = "lorenz",
      .description = "Lorenz system, y = x1 ([HG-EMB23])",
      .parameters = {
          {"sigma", "x1' = sigma (x2 - x1)", [](Lorenz& m) -> double& { return m.p.sigma; }},
          {"rho", "x2' = x1 (rho - x3) - x2", [](Lorenz& m) -> double& { return m.p.rho; }},
          {"beta", "x3' = x1 x2 - beta x3", [](Lorenz& m) -> double& { return m.p.beta; }}}}));
  r.add(model_entry(ModelDefinition<Duffing>{
      .name = "duffing", .description = "Duffing x1'=x2, x2'=x1-x1^3, y = x2 ([HG-EMB23])"}));
}

}  // namespace nlobs::detail
