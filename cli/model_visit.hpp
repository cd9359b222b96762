#pragma once
// The catalogue's models as their own C++ types: visit_model reads the model's name and
// parameters from its spec (strictly: an unknown key is an error naming it) and calls
//     f(model, default_step, default_scheme)
// with the continuous model. make_model discretises it; observers that need the continuous,
// AD-capable model (the MVT observer) build themselves from it.
#include <optional>
#include <string>

#include "json_reader.hpp"
#include "model_catalog.hpp"
#include "nlobs/models/discretization.hpp"
#include "nlobs/models/modified_chua.hpp"
#include "nlobs/models/systems.hpp"

namespace nlobs::cli {
namespace detail {
inline void set_parameter(JsonReader& r, const char* key, double& value) {
  if (auto v = r.number(key)) value = *v;
}
}  // namespace detail

// `spec` is the model object {"name", "parameters", ...}; its other keys are the caller's.
template <typename F>
decltype(auto) visit_model(JsonReader& spec, F&& f) {
  using detail::set_parameter;
  const std::string name = spec.required_text("name");
  std::optional<JsonReader> params = spec.object("parameters");
  static const nlohmann::json empty = nlohmann::json::object();
  JsonReader p = params ? *params : JsonReader(empty, spec.where() + ".parameters");
  if (name == "modified-chua") {
    ModifiedChuaParameters c;
    set_parameter(p, "alpha", c.alpha), set_parameter(p, "beta", c.beta),
        set_parameter(p, "a", c.a), set_parameter(p, "b", c.b), set_parameter(p, "d", c.d);
    p.finish({"alpha", "beta", "a", "b", "d"});
    std::optional<ModifiedChua> model;
    try {  // only the parameter check: f's own errors keep their own location
      model.emplace(c);
    } catch (const std::invalid_argument& e) {
      p.fail(e.what());
    }
    return f(std::move(*model), 0.05, Scheme::kEuler);
  }
  if (name == "cubic-chua") {
    CubicChua m;
    set_parameter(p, "a", m.p.a), set_parameter(p, "b", m.p.b), set_parameter(p, "m0", m.p.m0),
        set_parameter(p, "m1", m.p.m1);
    p.finish({"a", "b", "m0", "m1"});
    return f(m, 0.01, Scheme::kRk4);
  }
  if (name == "lorenz") {
    Lorenz m;
    set_parameter(p, "sigma", m.p.sigma), set_parameter(p, "rho", m.p.rho),
        set_parameter(p, "beta", m.p.beta);
    p.finish({"sigma", "rho", "beta"});
    return f(m, 0.01, Scheme::kRk4);
  }
  if (name == "duffing") {
    p.finish({});
    return f(Duffing{}, 0.01, Scheme::kRk4);
  }
  if (name == "van-der-pol") {
    VanDerPol m;
    set_parameter(p, "mu", m.mu);
    p.finish({"mu"});
    return f(m, 0.01, Scheme::kRk4);
  }
  if (name == "oscillator") {
    p.finish({});
    return f(OscillatorNonlinearOutput{}, 0.01, Scheme::kRk4);
  }
  if (name == "chaotic") {
    p.finish({});
    return f(ChaoticNoLinear{}, 0.01, Scheme::kRk4);
  }
  if (name == "robot") {
    FlexibleJointRobot m;
    set_parameter(p, "k1", m.p.k1), set_parameter(p, "damping", m.p.damping),
        set_parameter(p, "k2", m.p.k2), set_parameter(p, "gain", m.p.gain),
        set_parameter(p, "gravity", m.p.gravity);
    p.finish({"k1", "damping", "k2", "gain", "gravity"});
    return f(m, 0.01, Scheme::kRk4);
  }
  if (name == "lander") {
    LunarLander m;
    set_parameter(p, "g", m.p.g), set_parameter(p, "sigma", m.p.sigma),
        set_parameter(p, "alpha", m.p.alpha);
    p.finish({"g", "sigma", "alpha"});
    return f(m, 0.001, Scheme::kRk4);
  }
  if (name == "lander-f") {
    LunarLanderImmersed m;
    set_parameter(p, "g", m.p.g), set_parameter(p, "sigma", m.p.sigma),
        set_parameter(p, "alpha", m.p.alpha), set_parameter(p, "c", m.c);
    p.finish({"g", "sigma", "alpha", "c"});
    return f(m, 0.001, Scheme::kRk4);
  }
  if (name == "unknown-input") {
    UnknownInputIntegrator m;
    set_parameter(p, "amplitude", m.amplitude), set_parameter(p, "omega", m.omega);
    p.finish({"amplitude", "omega"});
    return f(m, 0.001, Scheme::kRk4);
  }
  if (name == "lti-injection") {
    LtiOutputInjection m;
    set_parameter(p, "a0", m.p.a0), set_parameter(p, "a1", m.p.a1),
        set_parameter(p, "gain", m.p.gain);
    p.finish({"a0", "a1", "gain"});
    return f(m, 0.01, Scheme::kRk4);
  }
  if (name == "pendulum") {
    PendulumTimeVaryingFriction m;
    set_parameter(p, "g", m.p.g), set_parameter(p, "length", m.p.length),
        set_parameter(p, "c0", m.p.c0), set_parameter(p, "c1", m.p.c1),
        set_parameter(p, "omega_c", m.p.omega_c), set_parameter(p, "a_max", m.p.a_max),
        set_parameter(p, "omega_a", m.p.omega_a);
    p.finish({"g", "length", "c0", "c1", "omega_c", "a_max", "omega_a"});
    if (!(m.p.length > 0.0)) p.fail("'length' must be > 0");
    return f(m, 0.01, Scheme::kRk4);
  }
  std::string list;
  for (const auto& m : model_catalog()) list += (list.empty() ? "" : ", ") + m.name;
  spec.fail("unknown model '" + name + "'; valid models: " + list);
}

}  // namespace nlobs::cli
