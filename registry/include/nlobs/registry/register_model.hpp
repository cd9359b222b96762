#pragma once
// A continuous model as a registry entry. One definition gives the scenario files, `nlobs list`
// and every observer type the model's conditions allow:
//
//   struct Rossler : nlobs::ModelSizes<3, 0, 1> { double a = 0.2, b = 0.2, c = 5.7; ... };
//   nlobs::model_registry().add(nlobs::model_entry(nlobs::ModelDefinition<Rossler>{
//       .name = "rossler",
//       .description = "Rössler attractor, y = x2",
//       .parameters = {{"a", "x2' = x1 + a x2", [](Rossler& m) -> double& { return m.a; }},
//                      {"c", "x3' = b + x3 (x1 - c)", [](Rossler& m) -> double& { return m.c; }}},
//   }));
//
// What the entry offers, by the model's type (one registration serves every size):
//   window estimators (any engine), EKF, UKF, MHE, Luenberger, sliding mode: every model
//     (AnyModel, AD Jacobians through ceres::Jet);
//   mvt: outputs <= states; the constructor checks y = [I_m 0] x;
//   high_gain: one output, no input;
//   modulating: a function modulating_form(const Model&) found by argument-dependent lookup
//     (nlobs/models/modulating_forms.hpp shows the form);
//   high_gain's "map": "explicit" and friends: hand_embedding(const Model&) likewise
//     (nlobs/models/embedded_forms.hpp).
//
// This header compiles the MVT and high-gain observers for the model (about 20 s for a
// three-state model at -O3); include it only where a model is registered.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <functional>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "nlobs/common/printable.hpp"
#include "nlobs/models/discretization.hpp"
#include "nlobs/observers/mvt/mvt_observer.hpp"
#include "nlobs/registry/hooks/high_gain_hook.hpp"
#include "nlobs/registry/hooks/modulating_hook.hpp"
#include "nlobs/registry/model_registry.hpp"

namespace nlobs {

// One number of a model's "parameters" object: `value` gives the field it sets.
template <typename Parameters>
struct ModelParameter {
  std::string key{};
  std::string meaning{};
  std::function<double&(Parameters&)> value{};
};

// `Parameters` is what the JSON keys set (the model itself by default, or its parameter struct
// when the model is built from one); `build` turns it into the model and may throw
// std::invalid_argument (InvalidInput) to refuse values, e.g. a length <= 0.
template <typename Model, typename Parameters = Model>
struct ModelDefinition {
  std::string name{};
  std::string description{};
  std::vector<ModelParameter<Parameters>> parameters{};
  double default_step = 0.01;
  Scheme default_scheme = Scheme::kRk4;
  int default_substeps = 1;  // a stiff or fast plant's own (DiscretizationOptions::substeps)
  Parameters defaults{};
  std::function<Model(const Parameters&)> build{};  // empty: the parameters are the model
};

namespace detail {

// The shortest text that reads back as v (100/7 shows all its digits, 0.11 stays 0.11).
inline std::string number_text(double v) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, v);
  return std::string(buffer, result.ptr);
}

template <typename Model>
constexpr bool kFixedSizes = Model::kStates != Eigen::Dynamic&& Model::kOutputs !=
                             Eigen::Dynamic&& Model::kInputs != Eigen::Dynamic;
template <typename Model>
constexpr bool kMvtFits = kFixedSizes<Model>&& Model::kOutputs <= Model::kStates;
template <typename Model>
constexpr bool kHighGainFits = kFixedSizes<Model>&& Model::kOutputs == 1 && Model::kInputs == 0;

template <typename Model>
ModelInstance model_instance(const std::string& name, Model model, double step,
                             const DiscretizationOptions& discretization) {
  ModelInstance out{
      .name = name,
      .discrete = AnyModel(name, Discretized<Model>(model, step, discretization), step),
      .continuous = model,
      .discretization = discretization};
  if constexpr (kMvtFits<Model>) {
    out.mvt.make = [model](const MvtOptions& options) -> std::unique_ptr<Observer> {
      return std::make_unique<MvtObserver<Model>>(model, options);
    };
  } else {
    out.mvt.unmet = "the MVT observer needs fixed sizes and y = [I_m 0] x (m <= n outputs)";
  }
  if constexpr (kHighGainFits<Model>) {
    out.high_gain.make = [model, name](const HighGainSpec& spec, const Eigen::VectorXd& start,
                                       double sample_time) {
      return build_high_gain(model, spec, start, sample_time, name);
    };
  } else {
    out.high_gain.unmet =
        "the observer needs an autonomous model with one output (x' = f(x), y = h(x)); this one "
        "has " +
        std::to_string(out.discrete.outputs()) + " output(s) and " +
        std::to_string(out.discrete.inputs()) + " input(s)";
  }
  if constexpr (HasModulatingForm<Model>) {
    out.modulating.make = [model](const ModulatingSpec& spec, const Eigen::VectorXd& start,
                                  double sample_time) {
      return build_modulating(modulating_form(model), spec, start, sample_time);
    };
  } else {
    out.modulating.unmet =
        "no canonical form for it (the model supplies one with a function "
        "modulating_form(const Model&), docs/extending.md)";
  }
  return out;
}

}  // namespace detail

template <typename Model, typename Parameters>
ModelEntry model_entry(ModelDefinition<Model, Parameters> definition) {
  static_assert(ContinuousModel<Model>, "model_entry needs a continuous model (vector_field, h)");
  if constexpr (!std::is_same_v<Model, Parameters>) {
    if (!definition.build) {
      throw InvalidInput("model '" + definition.name +
                         "': ModelDefinition::build is required when the parameters are not the "
                         "model");
    }
  }
  if (!(definition.default_step > 0.0) || !std::isfinite(definition.default_step)) {
    throw InvalidInput("model '" + definition.name + "': default_step must be finite and > 0");
  }
  ModelEntry entry;
  entry.name = definition.name;
  entry.description = definition.description;
  entry.default_step = definition.default_step;
  entry.default_scheme = definition.default_scheme;
  entry.default_substeps = definition.default_substeps;
  try {
    DiscretizationOptions{.substeps = definition.default_substeps}.validate();
  } catch (const InvalidInput& e) {
    throw InvalidInput("model '" + definition.name + "': default_substeps: " + e.what());
  }
  for (auto& p : definition.parameters) {
    const bool taken = std::any_of(entry.parameters.begin(), entry.parameters.end(),
                                   [&](const KeyInfo& k) { return k.key == p.key; });
    if (p.key.empty() || taken) {
      throw InvalidInput("model '" + definition.name + "': parameter key '" + p.key +
                         "' is empty or listed twice");
    }
    if (!p.value)
      throw InvalidInput("model '" + entry.name + "': parameter '" + p.key +
                         "' has no field (ModelParameter::value)");
    double default_value = 0.0;
    try {  // the user's hook, run once here: what it throws is refused by the model's name
      default_value = p.value(definition.defaults);
    } catch (...) {
      throw InvalidInput("model '" + definition.name + "': parameter '" + p.key +
                         "': its field (ModelParameter::value) threw: " + current_exception_text());
    }
    entry.parameters.push_back({p.key, p.meaning, detail::number_text(default_value)});
  }
  const auto build = [definition](const Parameters& p) -> Model {
    if (definition.build) return definition.build(p);
    if constexpr (std::is_same_v<Model, Parameters>) return p;
    throw InvalidInput("unreachable");  // refused above
  };
  std::optional<Model> probe;
  try {
    probe.emplace(build(definition.defaults));
  } catch (...) {
    throw InvalidInput("model '" + definition.name +
                       "': its build threw on the defaults: " + current_exception_text());
  }
  entry.states = probe->states();
  entry.inputs = probe->inputs();
  entry.outputs = probe->outputs();
  entry.families = {"window", "ekf", "ukf", "mhe", "luenberger", "sliding_mode"};
  if constexpr (detail::kMvtFits<Model>) entry.families.push_back("mvt");
  if constexpr (detail::kHighGainFits<Model>) entry.families.push_back("high_gain");
  if constexpr (detail::HasModulatingForm<Model>) entry.families.push_back("modulating");
  if (probe->outputs() == 1) entry.families.push_back("finite_difference");
  entry.make = [definition, build](JsonReader& reader, double step,
                                   const DiscretizationOptions& discretization) {
    Parameters p = definition.defaults;
    std::vector<std::string> keys;
    for (const auto& parameter : definition.parameters) {
      keys.push_back(parameter.key);
      if (auto v = reader.number(parameter.key)) {
        try {  // the user's hook
          parameter.value(p) = *v;
        } catch (...) {
          reader.fail("parameter '" + parameter.key + "' of model '" + definition.name +
                      "': its field (ModelParameter::value) threw: " + current_exception_text());
        }
      }
    }
    reader.finish(keys);
    std::optional<Model> model;
    try {  // the model's refusal names the parameters object
      model.emplace(build(p));
    } catch (const std::exception&) {  // a refusal of values: its message says which
      reader.fail(current_exception_text());
    } catch (...) {  // `throw 42`: nothing to quote, so name whose code it was
      reader.fail("model '" + definition.name + "': its build threw " + current_exception_text());
    }
    return detail::model_instance(definition.name, std::move(*model), step, discretization);
  };
  return entry;
}

}  // namespace nlobs
