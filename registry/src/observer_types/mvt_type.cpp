// "mvt": the mean-value-theorem observer of [BMH], built by the model's mvt hook (the observer
// needs the continuous model's own type, register_model.hpp). The spec is MvtOptions itself.
#include "builtin_observer_types.hpp"

namespace nlobs::detail {
namespace {

MvtOptions parse(JsonReader& o, const ModelInstance& model) {
  MvtOptions s;
  const std::string variant = o.text("variant").value_or("injection");
  if (variant != "injection" && variant != "published") {
    o.fail("'variant' must be injection (with the output-injection correction) or published");
  }
  s.variant = variant == "published" ? MvtVariant::kPublished : MvtVariant::kOutputInjection;
  s.name = o.name().value_or("mvt:" + variant);
  s.initial_error_estimate = o.required_vector("error_guess");
  if (s.initial_error_estimate.size() != model.discrete.states()) {
    o.fail("'error_guess' must have " + std::to_string(model.discrete.states()) +
           " entries (the model's states)");
  }
  s.eta = o.number("eta").value_or(1.0);
  if (!(s.eta >= 1.0)) o.fail("'eta' must be >= 1");
  s.injection_gain = o.number("injection_gain").value_or(10.0);
  if (!(s.injection_gain >= 0.0)) o.fail("'injection_gain' must be >= 0");
  try {
    s.beta.method = mvt_beta_method_from_string(o.text("beta_solver").value_or("per-row"));
  } catch (const InvalidInput&) {
    o.fail("'beta_solver' must be per-row, nlopt or ceres");
  }
  const std::string integrator = o.text("integrator").value_or("rk4");
  if (integrator != "rk4" && integrator != "dopri5") o.fail("'integrator' must be rk4 or dopri5");
  s.integrator = integrator == "dopri5" ? MvtIntegrator::kDopri5 : MvtIntegrator::kRk4;
  s.substeps = static_cast<int>(o.integer("substeps", 1, 1000).value_or(1));
  return s;
}

void write(const MvtOptions& s, nlohmann::json& out) {
  out["name"] = s.name;
  out["error_guess"] = std_vector(s.initial_error_estimate);
  out["eta"] = s.eta;
  out["variant"] = s.variant == MvtVariant::kPublished ? "published" : "injection";
  out["injection_gain"] = s.injection_gain;
  out["beta_solver"] = std::string(to_string(s.beta.method));
  out["integrator"] = s.integrator == MvtIntegrator::kDopri5 ? "dopri5" : "rk4";
  out["substeps"] = s.substeps;
}

}  // namespace

void add_mvt_type(ObserverTypeRegistry& registry) {
  registry.add(observer_type_entry(ObserverTypeDefinition<MvtOptions>{
      .name = "mvt",
      .description = "mean-value-theorem observer of [BMH]",
      .condition = "y = [I_m 0] x",
      .keys = {{"error_guess", "e(0), the guess of x(0) - xhat(0) (n numbers)", ""},
               {"name", "in reports", "mvt:<variant>"},
               {"variant", "injection (with the output-injection correction) | published",
                "injection"},
               {"injection_gain", "gamma >= 0 of the injection variant", "10"},
               {"eta", "eta >= 1 in G = eta diag(alpha)", "1"},
               {"beta_solver", "per-row | nlopt | ceres", "per-row"},
               {"integrator", "rk4 | dopri5", "rk4"},
               {"substeps", "RK4 steps per sample, 1..1000", "1"},
               initial_key()},
      .parse = parse,
      .write = write,
      .build = [](MvtOptions s, const ObserverBuild& b) -> std::unique_ptr<Observer> {
        s.initial_estimate = b.start;
        s.sample_time = b.model.discrete.sample_time();
        return b.model.mvt("mvt", b.model.name, s);
      }}));
}

}  // namespace nlobs::detail
