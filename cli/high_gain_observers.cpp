#include "high_gain_observers.hpp"

#include <type_traits>

#include "model_visit.hpp"
#include "nlobs/models/embedded_forms.hpp"
#include "nlobs/observers/high_gain/high_gain_observer.hpp"
#include "nlobs/observers/high_gain/lie_observability_map.hpp"
#include "nlobs/observers/high_gain/taylor_observability_map.hpp"

namespace nlobs::cli {
namespace {

std::vector<double> to_std(const Eigen::VectorXd& v) {
  return std::vector<double>(v.data(), v.data() + v.size());
}

// The hand expansion that belongs to a catalogue model (embedded_forms.hpp), if any. Lorenz and
// Van der Pol have theirs only at the documented parameters.
template <typename Model>
struct HandForm {
  using type = void;
};
template <>
struct HandForm<Duffing> {
  using type = DuffingEmbedding;
};
template <>
struct HandForm<OscillatorNonlinearOutput> {
  using type = OscillatorEmbedding;
};
template <>
struct HandForm<Lorenz> {
  using type = LorenzEmbedding;
};
template <>
struct HandForm<VanDerPol> {
  using type = VanDerPolEmbedding;
};

template <typename Model>
bool at_documented_parameters(const Model& m) {
  if constexpr (std::is_same_v<Model, Lorenz>) {
    const LorenzParameters d;
    return m.p.sigma == d.sigma && m.p.rho == d.rho && m.p.beta == d.beta;
  } else if constexpr (std::is_same_v<Model, VanDerPol>) {
    return m.mu == 1.0;
  } else {
    return true;
  }
}

template <typename Form>
constexpr bool has_alpha = requires(const Form f,
                                    const Eigen::Matrix<double, Form::kDimension, 1>& z) {
  f.alpha(z);
};
template <typename Form>
constexpr bool has_inverse = requires(const Form f,
                                      const Eigen::Matrix<double, Form::kDimension, 1>& z) {
  f.inverse(z);
};

template <typename Model>
std::unique_ptr<Observer> build(Model model, const HighGainSpec& spec, const Eigen::VectorXd& start,
                                double sample_time, const std::string& model_name) {
  using Form = typename HandForm<Model>::type;
  constexpr bool kHand = !std::is_void_v<Form>;
  const auto refuse = [&](const std::string& what) {
    throw InvalidInput("high_gain on model '" + model_name + "': " + what);
  };
  const bool hand_ok = [&] {
    if constexpr (kHand) return at_documented_parameters(model);
    return false;
  }();
  int N = spec.N;
  if constexpr (kHand) {
    if (N == 0) N = Form::kDimension;
  }
  if (N == 0) refuse("give 'N' (no hand-expanded embedding for this model)");
  const auto need_hand = [&](const char* what) {
    if (!hand_ok) {
      refuse(std::string(what) +
             " needs the model's hand-expanded embedding (duffing, oscillator, lorenz and "
             "van-der-pol at their documented parameters)");
    }
    if constexpr (kHand) {
      if (N != Form::kDimension) {
        refuse(std::string(what) + " exists for N = " + std::to_string(Form::kDimension) + " only");
      }
    }
  };
  HighGainDesign design;
  if (start.size() != Model::kStates) {
    refuse("'initial' must have " + std::to_string(Model::kStates) + " entries");
  }
  if (spec.initial_z && spec.initial_z->size() != N) {
    refuse("'initial_z' must have N = " + std::to_string(N) + " entries");
  }
  if (spec.map == "explicit") {
    need_hand("'map': explicit");
    if constexpr (kHand) design.map = std::make_shared<ExplicitObservabilityMap<Form>>();
  } else if (spec.map == "adolc" || (spec.map == "ad" && N > kMaxTaylorObservabilityOrder)) {
    design.map = std::make_shared<LieObservabilityMap>(model, N);
  } else {
    if (N > kMaxTaylorObservabilityOrder) {
      refuse("'map': taylor exists for N <= " + std::to_string(kMaxTaylorObservabilityOrder) +
             " (use ad or adolc)");
    }
    design.map = make_taylor_observability_map(model, N);
  }
  const bool hand_alpha = [&] {
    if constexpr (kHand) return has_alpha<Form> && hand_ok && N == Form::kDimension;
    return false;
  }();
  if (spec.map == "explicit" && (spec.alpha == "lie" || (spec.alpha == "auto" && !hand_alpha))) {
    refuse("α = L_f^N h needs a map built from the model ('map': ad, taylor or adolc)");
  }
  if (spec.alpha == "explicit" || (spec.alpha == "auto" && hand_alpha)) {
    if (!hand_alpha) refuse("'alpha': explicit needs a hand α (duffing N = 6, oscillator N = 4)");
    if constexpr (kHand) {
      if constexpr (has_alpha<Form>) design.alpha = explicit_alpha<Form>();
    }
  }
  if (spec.inverse) {
    need_hand("'inverse'");
    if constexpr (kHand) {
      if constexpr (has_inverse<Form>) {
        design.inverse = explicit_inverse<Form>();
      } else {
        refuse("'inverse': only the oscillator has an explicit inverse");
      }
    }
  }
  HighGainOptions o;
  o.sample_time = sample_time;
  o.theta = spec.theta;
  o.poles = spec.poles;
  o.coefficients = spec.coefficients;
  if (spec.saturation_p.size() || spec.saturation_box.size()) {
    SmoothSaturation s;
    s.R = spec.saturation_r;
    s.rho = spec.saturation_rho;
    if (spec.saturation_p.size()) {
      s.P = spec.saturation_p;
    } else {
      need_hand("'saturation.box'");
      if constexpr (kHand)
        s.P = saturation_weight_from_box(embedded_box_bound(Form{}, spec.saturation_box));
    }
    o.saturation = s;
  }
  o.start = spec.start == "predicted" ? ProjectionStart::kPredicted : ProjectionStart::kPrevious;
  o.integrator = spec.integrator == "rk4"     ? HighGainIntegrator::kRk4
                 : spec.integrator == "cvode" ? HighGainIntegrator::kCvode
                                              : HighGainIntegrator::kAuto;
  o.substeps = spec.substeps;
  o.jump_threshold = spec.jump_threshold;
  o.observability_floor = spec.observability_floor;
  o.residual_scale = spec.residual_scale;
  o.restart_residual = spec.restart_residual;
  o.restart_every = spec.restart_every;
  o.name = spec.name;
  o.initial_estimate = start;
  o.initial_embedded_estimate = spec.initial_z;
  if (spec.initial_z_from) {
    if (spec.initial_z_from->size() != Model::kStates) {
      refuse("'initial_z_from' must have " + std::to_string(Model::kStates) + " entries");
    }
    Eigen::VectorXd z(N);
    if (!design.map->value(*spec.initial_z_from, z)) refuse("q_N('initial_z_from') is not finite");
    o.initial_embedded_estimate = z;
  }
  // The engine spec belongs to the scenario: built here through the registry, with the
  // projection's tolerances. An explicit inverse needs none. The options are checked first, so
  // that a bad engine spec does not hide a bad option (the constructor checks them again).
  o.design = std::move(design);
  o.validate();
  std::unique_ptr<Engine<Model::kStates>> projection;
  if (!o.design.inverse) {
    projection = EngineRegistry<Model::kStates>::global().create(spec.projection,
                                                                 high_gain_projection_options());
  }
  return std::make_unique<HighGainObserver<Model>>(std::move(model), std::move(o),
                                                   std::move(projection));
}

}  // namespace

HighGainSpec parse_high_gain_spec(JsonReader& o) {
  HighGainSpec s;
  s.name = o.name().value_or("high_gain");
  if (auto v = o.integer("N", 2, 12)) s.N = static_cast<int>(*v);
  s.theta = o.number("theta").value_or(0.1);
  if (!(s.theta > 0.0)) o.fail("'theta' must be > 0");
  if (auto p = o.vector("poles")) s.poles = to_std(*p);
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

void write_high_gain_spec(const HighGainSpec& s, nlohmann::json& out) {
  out["name"] = s.name;
  if (s.N) out["N"] = s.N;
  out["theta"] = s.theta;
  if (!s.poles.empty()) out["poles"] = s.poles;
  if (s.coefficients.size()) out["coefficients"] = to_std(s.coefficients);
  out["map"] = s.map;
  out["alpha"] = s.alpha;
  out["inverse"] = s.inverse;
  if (s.saturation_p.size() || s.saturation_box.size()) {
    nlohmann::json sat{{"R", s.saturation_r}, {"rho", s.saturation_rho}};
    if (s.saturation_box.size()) {
      sat["box"] = to_std(s.saturation_box);
    } else {
      nlohmann::json rows = nlohmann::json::array();
      for (Eigen::Index i = 0; i < s.saturation_p.rows(); ++i) {
        rows.push_back(to_std(s.saturation_p.row(i).transpose()));
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
  if (s.initial_z) out["initial_z"] = to_std(*s.initial_z);
  if (s.initial_z_from) out["initial_z_from"] = to_std(*s.initial_z_from);
}

std::unique_ptr<Observer> make_high_gain_observer(const HighGainSpec& spec,
                                                  const nlohmann::json& model,
                                                  const Eigen::VectorXd& start, double sample_time,
                                                  const std::string& where) {
  JsonReader reader(model, where + ".model");
  const std::string model_name = model.value("name", std::string("?"));
  return visit_model(reader, [&](auto m, double, Scheme) -> std::unique_ptr<Observer> {
    using Model = decltype(m);
    if constexpr (Model::kOutputs == 1 && Model::kInputs == 0 && Model::kStates != Eigen::Dynamic) {
      return build(std::move(m), spec, start, sample_time, model_name);
    } else {
      throw InvalidInput("high_gain on model '" + model_name +
                         "': the observer needs an autonomous model with one output "
                         "(x' = f(x), y = h(x))");
    }
  });
}

}  // namespace nlobs::cli
