#include "modulating_observers.hpp"

#include <type_traits>

#include "model_visit.hpp"
#include "nlobs/observers/modulating/modulating_function_observer.hpp"
#include "nlobs/solvers/engine_registry.hpp"

namespace nlobs::cli {
namespace {

template <typename Form>
std::unique_ptr<Observer> build(Form form, const ModulatingSpec& spec, const Eigen::VectorXd& start,
                                double sample_time) {
  ModulatingOptions o;
  o.name = spec.name;
  o.initial_estimate = start;
  o.sample_time = sample_time;
  o.horizon = spec.horizon;
  o.quadrature = spec.quadrature == "trapezoid" ? Quadrature::kTrapezoid : Quadrature::kSimpson;
  o.kernel.order = spec.order;
  o.kernel.degree = spec.degree;
  o.kernel.noise_weights = spec.noise_weights;
  if (o.kernel.noise_weights.size() == 0) {
    Vector<Form::n> a;
    Matrix<Form::n, Form::p> b;
    form.coefficients(0.0, a, b);
    o.kernel.noise_weights = a;
  }
  o.sample_period = spec.sample_period;
  o.resample = spec.resample;
  o.resample_max_gap = spec.resample_max_gap;
  if (spec.disturbance_bound) {
    if constexpr (std::is_same_v<Form, PendulumForm>) {
      o.disturbance_gains = Eigen::Vector2d(1.0, 0.0);  // d enters η_0' (modulating_forms.hpp)
      o.disturbance_level = form.disturbance_level();
    } else {
      throw InvalidInput("'disturbance_bound': this model has no unknown disturbance");
    }
  }
  // The design engine from its spec after the options' own checks, so that a bad spec cannot
  // hide a bad option.
  o.validate();
  return std::make_unique<ModulatingFunctionObserver<Form>>(
      std::move(form), std::move(o),
      EngineRegistry<Eigen::Dynamic>::global().create(spec.engine,
                                                      modulating_kernel_solver_options()));
}

}  // namespace

ModulatingSpec parse_modulating_spec(JsonReader& o) {
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

void write_modulating_spec(const ModulatingSpec& s, nlohmann::json& out) {
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

std::unique_ptr<Observer> make_modulating_observer(const ModulatingSpec& spec,
                                                   const nlohmann::json& model,
                                                   const Eigen::VectorXd& start, double sample_time,
                                                   const std::string& where) {
  JsonReader reader(model, where + ".model");
  const std::string model_name = model.value("name", std::string("?"));
  return visit_model(reader, [&](auto m, double, Scheme) -> std::unique_ptr<Observer> {
    using Model = decltype(m);
    if constexpr (std::is_same_v<Model, LtiOutputInjection>) {
      return build(LtiInjectionForm{m.p}, spec, start, sample_time);
    } else if constexpr (std::is_same_v<Model, PendulumTimeVaryingFriction>) {
      return build(PendulumForm{m.p}, spec, start, sample_time);
    } else {
      throw std::invalid_argument(
          "modulating on model '" + model_name +
          "': no canonical form for it (the catalogue has lti-injection and pendulum; add a "
          "form in C++, docs/extending.md)");
    }
  });
}

}  // namespace nlobs::cli
