#include "mvt_observers.hpp"

#include "model_visit.hpp"
#include "nlobs/observers/mvt/mvt_observer.hpp"

namespace nlobs::cli {

MvtSpec parse_mvt_spec(JsonReader& o) {
  MvtSpec s;
  s.variant = o.text("variant").value_or("injection");
  if (s.variant != "injection" && s.variant != "published") {
    o.fail("'variant' must be injection (with the output-injection correction) or published");
  }
  s.name = o.name().value_or("mvt:" + s.variant);
  s.error_guess = o.required_vector("error_guess");
  s.eta = o.number("eta").value_or(1.0);
  if (!(s.eta >= 1.0)) o.fail("'eta' must be >= 1");
  s.injection_gain = o.number("injection_gain").value_or(10.0);
  if (!(s.injection_gain >= 0.0)) o.fail("'injection_gain' must be >= 0");
  s.beta_solver = o.text("beta_solver").value_or("per-row");
  try {
    mvt_beta_method_from_string(s.beta_solver);
  } catch (const InvalidInput&) {
    o.fail("'beta_solver' must be per-row, nlopt or ceres");
  }
  s.integrator = o.text("integrator").value_or("rk4");
  if (s.integrator != "rk4" && s.integrator != "dopri5")
    o.fail("'integrator' must be rk4 or dopri5");
  s.substeps = static_cast<int>(o.integer("substeps", 1, 1000).value_or(1));
  return s;
}

void write_mvt_spec(const MvtSpec& s, nlohmann::json& out) {
  out["name"] = s.name;
  out["error_guess"] =
      std::vector<double>(s.error_guess.data(), s.error_guess.data() + s.error_guess.size());
  out["eta"] = s.eta;
  out["variant"] = s.variant;
  out["injection_gain"] = s.injection_gain;
  out["beta_solver"] = s.beta_solver;
  out["integrator"] = s.integrator;
  out["substeps"] = s.substeps;
}

std::unique_ptr<Observer> make_mvt_observer(const MvtSpec& spec, const nlohmann::json& model,
                                            const Eigen::VectorXd& start, double sample_time,
                                            const std::string& where) {
  MvtOptions options;
  options.name = spec.name;
  options.initial_estimate = start;
  options.initial_error_estimate = spec.error_guess;
  options.sample_time = sample_time;
  options.eta = spec.eta;
  options.variant =
      spec.variant == "published" ? MvtVariant::kPublished : MvtVariant::kOutputInjection;
  options.injection_gain = spec.injection_gain;
  options.beta.method = mvt_beta_method_from_string(spec.beta_solver);
  options.integrator = spec.integrator == "dopri5" ? MvtIntegrator::kDopri5 : MvtIntegrator::kRk4;
  options.substeps = spec.substeps;
  JsonReader reader(model, where + ".model");
  return visit_model(reader, [&](auto m, double, Scheme) -> std::unique_ptr<Observer> {
    using Model = decltype(m);
    return std::make_unique<MvtObserver<Model>>(std::move(m), options);
  });
}

}  // namespace nlobs::cli
