// "high_gain": the high-gain observer in embedded coordinates of [HG-EMB23], built by the
// model's high-gain hook (hooks/high_gain_hook.hpp: the map and α from the model, or from its
// hand embedding).
#include "builtin_observer_types.hpp"

namespace nlobs::detail {
namespace {

HighGainSpec parse(JsonReader& o, const ModelInstance&) {
  HighGainSpec s;
  s.name = o.name().value_or("high_gain");
  if (auto v = o.integer("N", 2, 12)) s.N = static_cast<int>(*v);
  s.theta = o.number("theta").value_or(0.1);
  if (!(s.theta > 0.0)) o.fail("'theta' must be > 0");
  if (auto p = o.vector("poles")) s.poles = std_vector(*p);
  if (auto c = o.vector("coefficients")) s.coefficients = *c;
  s.map = o.text("map").value_or("ad");
  if (s.map != "ad" && s.map != "taylor" && s.map != "adolc" && s.map != "explicit") {
    o.fail("'map' must be ad, taylor, adolc or explicit");
  }
  s.alpha = o.text("alpha").value_or("auto");
  if (s.alpha != "auto" && s.alpha != "explicit" && s.alpha != "lie") {
    o.fail("'alpha' must be auto, explicit or lie");
  }
  s.inverse = o.boolean("inverse").value_or(false);
  if (auto sat = o.object("saturation")) {
    const auto p = sat->matrix("P");
    const auto d = sat->vector("P_diagonal");
    const auto b = sat->vector("box");
    if ((p ? 1 : 0) + (d ? 1 : 0) + (b ? 1 : 0) != 1) {
      sat->fail("give one of 'P', 'P_diagonal' or 'box'");
    }
    if (p) s.saturation_p = *p;
    if (d) s.saturation_p = d->asDiagonal();
    if (b) s.saturation_box = *b;
    s.saturation_r = sat->number("R").value_or(1.0);
    s.saturation_rho = sat->number("rho").value_or(2.0);
    sat->finish({"P", "P_diagonal", "box", "R", "rho"});
  }
  s.projection = o.text("projection").value_or("ceres");
  s.start = o.text("start").value_or("previous");
  if (s.start != "previous" && s.start != "predicted")
    o.fail("'start' must be previous or predicted");
  s.integrator = o.text("integrator").value_or("auto");
  if (s.integrator != "auto" && s.integrator != "rk4" && s.integrator != "cvode") {
    o.fail("'integrator' must be auto, rk4 or cvode");
  }
  s.substeps = static_cast<int>(o.integer("substeps", 1, 1000).value_or(1));
  s.jump_threshold = o.number("jump_threshold").value_or(s.jump_threshold);
  s.observability_floor = o.number("observability_floor").value_or(s.observability_floor);
  s.residual_scale = o.number("residual_scale").value_or(s.residual_scale);
  s.restart_residual = o.number("restart_residual").value_or(s.restart_residual);
  s.restart_every =
      static_cast<int>(o.integer("restart_every", 1, 1000000).value_or(s.restart_every));
  s.initial_z = o.vector("initial_z");
  s.initial_z_from = o.vector("initial_z_from");
  if (s.initial_z && s.initial_z_from) o.fail("give 'initial_z' or 'initial_z_from', not both");
  return s;
}

void write(const HighGainSpec& s, nlohmann::json& out) {
  out["name"] = s.name;
  if (s.N) out["N"] = s.N;
  out["theta"] = s.theta;
  if (!s.poles.empty()) out["poles"] = s.poles;
  if (s.coefficients.size()) out["coefficients"] = std_vector(s.coefficients);
  out["map"] = s.map;
  out["alpha"] = s.alpha;
  out["inverse"] = s.inverse;
  if (s.saturation_p.size() || s.saturation_box.size()) {
    nlohmann::json sat{{"R", s.saturation_r}, {"rho", s.saturation_rho}};
    if (s.saturation_box.size()) {
      sat["box"] = std_vector(s.saturation_box);
    } else {
      nlohmann::json rows = nlohmann::json::array();
      for (Eigen::Index i = 0; i < s.saturation_p.rows(); ++i) {
        rows.push_back(std_vector(s.saturation_p.row(i).transpose()));
      }
      sat["P"] = rows;
    }
    out["saturation"] = sat;
  }
  out["projection"] = s.projection;
  out["start"] = s.start;
  out["integrator"] = s.integrator;
  out["substeps"] = s.substeps;
  out["jump_threshold"] = s.jump_threshold;
  out["observability_floor"] = s.observability_floor;
  out["residual_scale"] = s.residual_scale;
  out["restart_residual"] = s.restart_residual;
  out["restart_every"] = s.restart_every;
  if (s.initial_z) out["initial_z"] = std_vector(*s.initial_z);
  if (s.initial_z_from) out["initial_z_from"] = std_vector(*s.initial_z_from);
}

}  // namespace

void add_high_gain_type(ObserverTypeRegistry& registry) {
  registry.add(observer_type_entry(ObserverTypeDefinition<HighGainSpec>{
      .name = "high_gain",
      .description = "high-gain observer in embedded coordinates of [HG-EMB23]",
      .condition = "one output, no input",
      .keys = {{"N", "embedding dimension, 2..12", "the hand embedding's N"},
               {"theta", "theta > 0: gains 1/theta^i", "0.1"},
               {"poles", "the N poles of the gain polynomial", "all at -1"},
               {"coefficients", "the gain polynomial's coefficients instead of poles", ""},
               {"map", "ad (taylor for N <= 8, else adolc) | taylor | adolc | explicit (hand)",
                "ad"},
               {"alpha", "auto | explicit | lie (L_f^N h along the prediction)", "auto"},
               {"inverse", "the explicit inverse instead of the projection", "false"},
               {"saturation", "{P | P_diagonal | box, R, rho}: smooth saturation of zhat", "none"},
               {"projection", "engine spec of the projection onto the embedding", "ceres"},
               {"start", "previous | predicted: the projection's first guess", "previous"},
               {"integrator", "auto | rk4 | cvode", "auto"},
               {"substeps", "integration steps per sample, 1..1000", "1"},
               {"jump_threshold", "a projection jump larger than this is counted", "0.1"},
               {"observability_floor", "smallest singular value of dq/dx accepted", "0.01"},
               {"residual_scale", "projection residual scale", "0.1"},
               {"restart_residual", "restart the projection above this residual", "0.01"},
               {"restart_every", "samples between projection restarts, >= 1", "1"},
               {"initial_z", "zhat(0) (N numbers)", "q_N(initial)"},
               {"initial_z_from", "zhat(0) = q_N(this x)", ""},
               {"name", "in reports", "high_gain"},
               initial_key()},
      .parse = parse,
      .write = write,
      .build = [](const HighGainSpec& s, const ObserverBuild& b) -> std::unique_ptr<Observer> {
        return b.model.high_gain("high_gain", b.model.name, s, b.start,
                                 b.model.discrete.sample_time());
      }}));
}

}  // namespace nlobs::detail
