#pragma once
// Models by name for scenario files and the CLI. A model spec
//   {"name": "lorenz", "parameters": {"sigma": 10}, "scheme": "rk4", "step": 0.01, "substeps": 1,
//    "absolute_tolerance": 1e-8, "relative_tolerance": 1e-6}
// becomes a ModelInstance: the discretised model every observer can run on (AnyModel, with AD
// Jacobians), and the hooks of the observer families that need the continuous model's own C++
// type (MVT, high-gain, modulating), each empty with the reason when the model does not meet
// the family's condition.
//
// The built-in models are registered exactly as a user's are: with model_entry<Model>() from
// register_model.hpp, which derives everything here from the model type and a short
// definition. This header is light (no observer is included): it is what the CLI's scenario
// code includes.
//
// An observer type that needs the model's own C++ type and is not one of the families above (a
// plugin's, say: a fixed-size filter, a form only some models have) reaches it through
// ModelInstance::model_as<Model>() or build_on_model<Models...>() below, for the model types it
// knows: its own and the built-in ones, whose headers are installed (examples/plugin shows one).
#include <Eigen/Core>
#include <any>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "nlobs/common/named_registry.hpp"
#include "nlobs/models/discretization.hpp"
#include "nlobs/observers/core/any_model.hpp"
#include "nlobs/observers/core/observer.hpp"
#include "nlobs/observers/mvt/mvt_options.hpp"
#include "nlobs/registry/high_gain_spec.hpp"
#include "nlobs/registry/json_reader.hpp"
#include "nlobs/registry/modulating_spec.hpp"

namespace nlobs {

// An observer family's way to be built on one model, or why it cannot be: `make` is empty
// exactly when `unmet` says which condition the model does not meet.
template <typename... Args>
struct ModelHook {
  std::function<std::unique_ptr<Observer>(Args...)> make;
  std::string unmet;
  explicit operator bool() const { return static_cast<bool>(make); }
  // Builds, or throws InvalidInput "<family> on model '<name>': <unmet>".
  std::unique_ptr<Observer> operator()(const std::string& family, const std::string& model,
                                       Args... args) const {
    if (!make) throw InvalidInput(family + " on model '" + model + "': " + unmet);
    return make(std::forward<Args>(args)...);
  }
};

struct ModelInstance {
  std::string name;  // the registry's name
  AnyModel discrete;
  // The continuous model, as the C++ type it was registered with (a copy of the one `discrete`
  // integrates), and how `discrete` integrates it over discrete.sample_time(): enough to build
  // Discretized<Model>(*model_as<Model>(), discrete.sample_time(), discretization) again.
  std::any continuous{};
  DiscretizationOptions discretization{.scheme = Scheme::kRk4};
  // MvtOptions::sample_time is the discrete model's.
  ModelHook<const MvtOptions&> mvt{};
  // (spec, initial estimate, sample time)
  ModelHook<const HighGainSpec&, const Eigen::VectorXd&, double> high_gain{};
  ModelHook<const ModulatingSpec&, const Eigen::VectorXd&, double> modulating{};

  // The continuous model if it is a `Model` (the exact type model_entry<Model>() registered),
  // else null.
  template <typename Model>
  const Model* model_as() const {
    return std::any_cast<Model>(&continuous);
  }
};

// An observer type's build for the model types it is written for: calls build(model) with the
// instance's continuous model as the first of `Models` it is, and returns what build returns.
// Throws InvalidInput "<family> on model '<name>': <unmet>" when it is none of them, `unmet`
// saying which models the type takes.
template <typename... Models, typename Build>
auto build_on_model(const ModelInstance& instance, const std::string& family,
                    const std::string& unmet, Build&& build)
    -> decltype(build(std::declval<const std::tuple_element_t<0, std::tuple<Models...>>&>())) {
  static_assert(sizeof...(Models) > 0, "build_on_model needs at least one model type");
  using Result =
      decltype(build(std::declval<const std::tuple_element_t<0, std::tuple<Models...>>&>()));
  std::optional<Result> built;
  // The first matching type builds; the fold stops there.
  (void)((instance.model_as<Models>() != nullptr
              ? (built.emplace(build(*instance.model_as<Models>())), true)
              : false) ||
         ...);
  if (!built) throw InvalidInput(family + " on model '" + instance.name + "': " + unmet);
  return std::move(*built);
}

struct ModelEntry {
  std::string name;
  std::string description;  // one line: the equations' source, the output
  std::vector<KeyInfo> parameters;
  double default_step = 0.01;
  Scheme default_scheme = Scheme::kRk4;
  int default_substeps = 1;
  Eigen::Index states = 0, inputs = 0, outputs = 0;
  // Which hooks can exist for this model at all (the rest of the conditions are checked when
  // the observer is built): for `nlobs list models`.
  std::vector<std::string> families;
  // Reads the "parameters" object strictly (an unknown key is an error naming it; a value the
  // model refuses fails naming the parameters object) and discretises with (step, options).
  std::function<ModelInstance(JsonReader& parameters, double step,
                              const DiscretizationOptions& discretization)>
      make;
};

// NamedRegistry refuses a model without make, or with a default_substeps out of range (a
// hand-built entry: model_entry checks its definition's).
inline std::string missing_part(const ModelEntry& e) {
  if (!e.make) return "has no make";
  if (e.default_substeps < 1 || e.default_substeps > DiscretizationOptions::kMostSubsteps) {
    return "has default_substeps = " + std::to_string(e.default_substeps) + ", out of range [1, " +
           std::to_string(DiscretizationOptions::kMostSubsteps) + "]";
  }
  return {};
}

using ModelRegistry = NamedRegistry<ModelEntry>;

// The process-wide registry: every built-in model, then what plugins and user code add.
ModelRegistry& model_registry();

// The instance a model spec {"name", "parameters", "scheme", "step", "substeps",
// "absolute_tolerance", "relative_tolerance"} describes (scheme: euler, rk4, dopri5 or sdirk3;
// the rest DiscretizationOptions' fields; the entry's defaults when absent). Throws
// std::invalid_argument naming the key path on any problem (an unknown name lists the valid
// ones).
ModelInstance make_model_instance(JsonReader& spec,
                                  const ModelRegistry& registry = model_registry());

}  // namespace nlobs
