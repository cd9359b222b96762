#include "model_catalog.hpp"

#include "nlobs/models/modified_chua.hpp"
#include "nlobs/models/systems.hpp"

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

void set(JsonReader& r, const char* key, double& value) {
  if (auto v = r.number(key)) value = *v;
}

}  // namespace

const std::vector<ModelInfo>& model_catalog() {
  static const std::vector<ModelInfo> models = {
      {"modified-chua",
       "modified Chua attractor, y = x1 (METHODS 1); Euler T = 0.05",
       {"alpha=10.82", "beta=14.286", "a=1.3", "b=0.11", "d=1"}},
      {"cubic-chua",
       "Chua circuit with cubic nonlinearity, y = x2 (METHODS 3)",
       {"a=9.5", "b=100/7", "m0=-8/7", "m1=4/63"}},
      {"lorenz", "Lorenz system, y = x1 (METHODS 5)", {"sigma=10", "rho=28", "beta=8/3"}},
      {"duffing", "Duffing x1'=x2, x2'=x1-x1^3, y = x2 (METHODS 5)", {}},
      {"van-der-pol", "Van der Pol oscillator, y = x2 (METHODS 5)", {"mu=1"}},
      {"oscillator", "harmonic oscillator, y = x1^2 + x1 (METHODS 5)", {}},
      {"chaotic", "chaotic system without linear term, y = (x1, x2) (METHODS 2)", {}},
      {"robot",
       "flexible-joint robot, 1 input, y = (x1, x2, x3) (METHODS 2)",
       {"k1=48.6", "damping=1.25", "k2=19.5", "gain=21.6", "gravity=3.33"}},
      {"lander",
       "lunar lander, 1 input, y = x1, domain x3 > 0 (METHODS 3)",
       {"g=1.63", "sigma=50", "alpha=200"}},
      {"lander-f",
       "lunar lander with f = exp(c sin t) as state x4, y = x1, domain x3 > 0 (METHODS 3)",
       {"g=1.63", "sigma=50", "alpha=200", "c=6"}},
      {"unknown-input",
       "x' = u + f, f = A sin(omega t) as state x2, y = x1 (METHODS 3, example 3)",
       {"amplitude=3", "omega=pi"}},
      {"pendulum",
       "pendulum with time-varying friction, y = angle (METHODS 4)",
       {"g=9.81", "length=1", "c0=0.5", "c1=0.2", "omega_c=1", "a_max=0", "omega_a=2"}},
  };
  return models;
}

AnyModel make_model(JsonReader& spec) {
  const std::string name = spec.required_text("name");
  std::optional<JsonReader> params = spec.object("parameters");
  static const nlohmann::json empty = nlohmann::json::object();
  JsonReader p = params ? *params : JsonReader(empty, spec.where() + ".parameters");
  AnyModel model = [&]() -> AnyModel {
    if (name == "modified-chua") {
      ModifiedChuaParameters c;
      set(p, "alpha", c.alpha), set(p, "beta", c.beta), set(p, "a", c.a), set(p, "b", c.b),
          set(p, "d", c.d);
      p.finish({"alpha", "beta", "a", "b", "d"});
      try {
        return discretize(name, ModifiedChua(c), spec, 0.05, Scheme::kEuler);
      } catch (const std::invalid_argument& e) {
        spec.fail(e.what());
      }
    }
    if (name == "cubic-chua") {
      CubicChua m;
      set(p, "a", m.p.a), set(p, "b", m.p.b), set(p, "m0", m.p.m0), set(p, "m1", m.p.m1);
      p.finish({"a", "b", "m0", "m1"});
      return discretize(name, m, spec, 0.01, Scheme::kRk4);
    }
    if (name == "lorenz") {
      Lorenz m;
      set(p, "sigma", m.p.sigma), set(p, "rho", m.p.rho), set(p, "beta", m.p.beta);
      p.finish({"sigma", "rho", "beta"});
      return discretize(name, m, spec, 0.01, Scheme::kRk4);
    }
    if (name == "duffing") {
      p.finish({});
      return discretize(name, Duffing{}, spec, 0.01, Scheme::kRk4);
    }
    if (name == "van-der-pol") {
      VanDerPol m;
      set(p, "mu", m.mu);
      p.finish({"mu"});
      return discretize(name, m, spec, 0.01, Scheme::kRk4);
    }
    if (name == "oscillator") {
      p.finish({});
      return discretize(name, OscillatorNonlinearOutput{}, spec, 0.01, Scheme::kRk4);
    }
    if (name == "chaotic") {
      p.finish({});
      return discretize(name, ChaoticNoLinear{}, spec, 0.01, Scheme::kRk4);
    }
    if (name == "robot") {
      FlexibleJointRobot m;
      set(p, "k1", m.p.k1), set(p, "damping", m.p.damping), set(p, "k2", m.p.k2),
          set(p, "gain", m.p.gain), set(p, "gravity", m.p.gravity);
      p.finish({"k1", "damping", "k2", "gain", "gravity"});
      return discretize(name, m, spec, 0.01, Scheme::kRk4);
    }
    if (name == "lander") {
      LunarLander m;
      set(p, "g", m.p.g), set(p, "sigma", m.p.sigma), set(p, "alpha", m.p.alpha);
      p.finish({"g", "sigma", "alpha"});
      return discretize(name, m, spec, 0.001, Scheme::kRk4);
    }
    if (name == "lander-f") {
      LunarLanderImmersed m;
      set(p, "g", m.p.g), set(p, "sigma", m.p.sigma), set(p, "alpha", m.p.alpha), set(p, "c", m.c);
      p.finish({"g", "sigma", "alpha", "c"});
      return discretize(name, m, spec, 0.001, Scheme::kRk4);
    }
    if (name == "unknown-input") {
      UnknownInputIntegrator m;
      set(p, "amplitude", m.amplitude), set(p, "omega", m.omega);
      p.finish({"amplitude", "omega"});
      return discretize(name, m, spec, 0.001, Scheme::kRk4);
    }
    if (name == "pendulum") {
      PendulumTimeVaryingFriction m;
      set(p, "g", m.p.g), set(p, "length", m.p.length), set(p, "c0", m.p.c0), set(p, "c1", m.p.c1),
          set(p, "omega_c", m.p.omega_c), set(p, "a_max", m.p.a_max),
          set(p, "omega_a", m.p.omega_a);
      p.finish({"g", "length", "c0", "c1", "omega_c", "a_max", "omega_a"});
      return discretize(name, m, spec, 0.01, Scheme::kRk4);
    }
    std::string list;
    for (const auto& m : model_catalog()) list += (list.empty() ? "" : ", ") + m.name;
    spec.fail("unknown model '" + name + "'; valid models: " + list);
  }();
  spec.finish({"name", "parameters", "scheme", "step"});
  return model;
}

}  // namespace nlobs::cli
