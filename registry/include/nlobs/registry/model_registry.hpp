#pragma once
// Models by name for scenario files and the CLI. A model spec
//   {"name": "lorenz", "parameters": {"sigma": 10}, "scheme": "rk4", "step": 0.01}
// becomes a ModelInstance: the discretised model every observer can run on (AnyModel, with AD
// Jacobians), and the hooks of the observer families that need the continuous model's own C++
// type (MVT, high-gain, modulating), each empty with the reason when the model does not meet
// the family's condition.
//
// The built-in models are registered exactly as a user's are: with model_entry<Model>() from
// register_model.hpp, which derives everything here from the model type and a short
// definition. This header is light (no observer is included): it is what the CLI's scenario
// code includes.
#include <Eigen/Core>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "nlobs/models/discretization.hpp"
#include "nlobs/observers/core/any_model.hpp"
#include "nlobs/observers/core/observer.hpp"
#include "nlobs/observers/mvt/mvt_options.hpp"
#include "nlobs/registry/high_gain_spec.hpp"
#include "nlobs/registry/json_reader.hpp"
#include "nlobs/registry/modulating_spec.hpp"
#include "nlobs/registry/named_registry.hpp"

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
  // MvtOptions::sample_time is the discrete model's.
  ModelHook<const MvtOptions&> mvt;
  // (spec, initial estimate, sample time)
  ModelHook<const HighGainSpec&, const Eigen::VectorXd&, double> high_gain;
  ModelHook<const ModulatingSpec&, const Eigen::VectorXd&, double> modulating;
};

struct ModelEntry {
  std::string name;
  std::string description;  // one line: the equations' source, the output
  std::vector<KeyInfo> parameters;
  double default_step = 0.01;
  Scheme default_scheme = Scheme::kRk4;
  Eigen::Index states = 0, inputs = 0, outputs = 0;
  // Which hooks can exist for this model at all (the rest of the conditions are checked when
  // the observer is built): for `nlobs list models`.
  std::vector<std::string> families;
  // Reads the "parameters" object strictly (an unknown key is an error naming it; a value the
  // model refuses fails naming the parameters object) and discretises with (step, scheme).
  std::function<ModelInstance(JsonReader& parameters, double step, Scheme scheme)> make;
};

using ModelRegistry = NamedRegistry<ModelEntry>;

// The process-wide registry: every built-in model, then what plugins and user code add.
ModelRegistry& model_registry();

// The instance a model spec {"name", "parameters", "scheme", "step"} describes. Throws
// std::invalid_argument naming the key path on any problem (an unknown name lists the valid
// ones).
ModelInstance make_model_instance(JsonReader& spec,
                                  const ModelRegistry& registry = model_registry());

}  // namespace nlobs
