// "modulating": the modulating-function algebraic observer of [MF-LTV], built by the model's
// modulating hook on the canonical form the model supplies (hooks/modulating_hook.hpp).
#include "builtin_observer_types.hpp"

namespace nlobs::detail {
namespace {

ModulatingSpec parse(JsonReader& o, const ModelInstance&) {
  ModulatingSpec s;
  s.name = o.name().value_or("modulating");
  s.horizon = o.number("horizon").value_or(1.0);
  if (!(s.horizon > 0.0)) o.fail("'horizon' must be > 0");
  if (auto v = o.integer("order", 1, 20)) s.order = static_cast<int>(*v);
  if (auto v = o.integer("degree", 1, 29)) s.degree = static_cast<int>(*v);
  if (auto w = o.vector("noise_weights")) s.noise_weights = *w;
  s.engine = o.text("engine").value_or("ceres");
  s.quadrature = o.text("quadrature").value_or("simpson");
  if (s.quadrature != "simpson" && s.quadrature != "trapezoid") {
    o.fail("'quadrature' must be simpson or trapezoid");
  }
  s.sample_period = o.number("sample_period").value_or(0.0);
  if (!(s.sample_period >= 0.0)) o.fail("'sample_period' must be >= 0 (0: every sample)");
  s.resample = o.boolean("resample").value_or(false);
  s.resample_max_gap = o.number("resample_max_gap").value_or(0.0);
  if (!(s.resample_max_gap >= 0.0)) o.fail("'resample_max_gap' must be >= 0 (0: 4 steps)");
  s.disturbance_bound = o.boolean("disturbance_bound").value_or(false);
  return s;
}

void write(const ModulatingSpec& s, nlohmann::json& out) {
  out["name"] = s.name;
  out["horizon"] = s.horizon;
  if (s.order) out["order"] = s.order;
  if (s.degree) out["degree"] = s.degree;
  if (s.noise_weights.size()) {
    out["noise_weights"] = std::vector<double>(s.noise_weights.data(),
                                               s.noise_weights.data() + s.noise_weights.size());
  }
  out["engine"] = s.engine;
  out["quadrature"] = s.quadrature;
  out["sample_period"] = s.sample_period;
  out["resample"] = s.resample;
  if (s.resample_max_gap > 0.0) out["resample_max_gap"] = s.resample_max_gap;
  out["disturbance_bound"] = s.disturbance_bound;
}

}  // namespace

void add_modulating_type(ObserverTypeRegistry& registry) {
  registry.add(observer_type_entry(ObserverTypeDefinition<ModulatingSpec>{
      .name = "modulating",
      .description = "modulating-function algebraic observer of [MF-LTV]",
      .condition = "a canonical form (modulating_form)",
      .keys = {{"horizon", "T > 0 (s): the window of the modulating functions", "1"},
               {"order", "derivatives the kernels annihilate, 1..20", "n"},
               {"degree", "polynomial degree of the kernels, 1..29", "order + n - 1"},
               {"noise_weights", "weights of the noise-optimal design", "the form's a_i(0)"},
               {"engine", "engine spec of the kernel design", "ceres"},
               {"quadrature", "simpson | trapezoid", "simpson"},
               {"sample_period", "outputs every this many seconds; 0: every sample", "0"},
               {"resample", "resample irregular outputs onto the grid", "false"},
               {"resample_max_gap", "largest gap bridged when resampling; 0: 4 steps", "0"},
               {"disturbance_bound", "Theorem 1's bound from the model's disturbance level",
                "false"},
               {"name", "in reports", "modulating"},
               initial_key()},
      .parse = parse,
      .write = write,
      .build = [](const ModulatingSpec& s, const ObserverBuild& b) -> std::unique_ptr<Observer> {
        return b.model.modulating("modulating", b.model.name, s, b.start,
                                  b.model.discrete.sample_time());
      }}));
}

}  // namespace nlobs::detail
