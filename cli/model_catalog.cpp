#include "model_catalog.hpp"

#include "model_visit.hpp"

namespace nlobs::cli {
namespace {

template <typename Model>
AnyModel discretize(const std::string& name, Model model, JsonReader& spec, double default_step,
                    Scheme default_scheme) {
  Scheme scheme = default_scheme;
  if (auto s = spec.text("scheme")) {
    if (*s == "euler") {
      scheme = Scheme::kEuler;
    } else if (*s == "rk4") {
      scheme = Scheme::kRk4;
    } else {
      spec.fail("scheme '" + *s + "' is not euler or rk4");
    }
  }
  const double step = spec.number("step").value_or(default_step);
  try {
    return AnyModel(name, Discretized<Model>(std::move(model), step, scheme), step);
  } catch (const std::invalid_argument& e) {
    spec.fail(e.what());
  }
}

}  // namespace

const std::vector<ModelInfo>& model_catalog() {
  static const std::vector<ModelInfo> models = {
      {"modified-chua",
       "modified Chua attractor, y = x1 ([MGFF23]); Euler T = 0.05",
       {"alpha=10.82", "beta=14.286", "a=1.3", "b=0.11", "d=1"}},
      {"cubic-chua",
       "Chua circuit with cubic nonlinearity, y = x2 ([FFMG19])",
       {"a=9.5", "b=100/7", "m0=-8/7", "m1=4/63"}},
      {"lorenz", "Lorenz system, y = x1 ([HG-EMB23])", {"sigma=10", "rho=28", "beta=8/3"}},
      {"duffing", "Duffing x1'=x2, x2'=x1-x1^3, y = x2 ([HG-EMB23])", {}},
      {"van-der-pol", "Van der Pol oscillator, y = x2 ([HG-EMB23])", {"mu=1"}},
      {"oscillator", "harmonic oscillator, y = x1^2 + x1 ([HG-EMB23])", {}},
      {"chaotic", "chaotic system without linear term, y = (x1, x2) ([BMH])", {}},
      {"robot",
       "flexible-joint robot, 1 input, y = (x1, x2, x3) ([BMH])",
       {"k1=48.6", "damping=1.25", "k2=19.5", "gain=21.6", "gravity=3.33"}},
      {"lander",
       "lunar lander, 1 input, y = x1, domain x3 > 0 ([FFMG19])",
       {"g=1.63", "sigma=50", "alpha=200"}},
      {"lander-f",
       "lunar lander with f = exp(c sin t) as state x4, y = x1, domain x3 > 0 ([FFMG19])",
       {"g=1.63", "sigma=50", "alpha=200", "c=6"}},
      {"unknown-input",
       "x' = u + f, f = A sin(omega t) as state x2, y = x1 ([FFMG19], example 3)",
       {"amplitude=3", "omega=pi"}},
      {"lti-injection",
       "x1'=x2, x2'=-a0 x1-a1 x2+gain sin(y), y = x1 ([MF-LTV])",
       {"a0=1", "a1=0.5", "gain=1"}},
      {"pendulum",
       "pendulum with time-varying friction, y = angle ([MF-LTV])",
       {"g=9.81", "length=1", "c0=0.5", "c1=0.2", "omega_c=1", "a_max=0", "omega_a=2"}},
  };
  return models;
}

AnyModel make_model(JsonReader& spec) {
  const std::string name = spec.required_text("name");
  AnyModel model =
      visit_model(spec, [&](auto m, double default_step, Scheme default_scheme) -> AnyModel {
        return discretize(name, std::move(m), spec, default_step, default_scheme);
      });
  spec.finish({"name", "parameters", "scheme", "step"});
  return model;
}

}  // namespace nlobs::cli
