#pragma once
// Observer types by name for scenario files: an entry of a scenario's "observers" array
//   {"type": "ekf", "process_covariance": ..., "initial": [...], "model": {...}}
// is read by its type's entry (strictly: every key it does not list is an error naming it),
// written back by the same entry (a run's scenario.json), and built on the scenario's model.
// The built-in types (window, luenberger, sliding_mode, ekf, pi_bank, mvt, high_gain,
// modulating, finite_difference) are registered exactly as a user's are, with
// observer_type_entry() below.
//
// Two keys are read for every type that lists them: "initial" (the observer's start estimate;
// default the scenario's initial guess) and "model" (its own design model, a model spec with
// the scenario model's sizes and sample time).
#include <any>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "nlobs/common/named_registry.hpp"
#include "nlobs/observers/core/observer.hpp"
#include "nlobs/registry/json_reader.hpp"
#include "nlobs/registry/model_registry.hpp"

namespace nlobs {

// What an observer type's build gets.
struct ObserverBuild {
  const ModelInstance& model;       // the scenario's model
  const AnyModel& design;           // the observer's "model", or model.discrete
  const Eigen::VectorXd& start;     // "initial", or the scenario's initial guess
  const std::string& where;         // "scenario.observers[2]", for messages
  bool trace_first_window = false;  // window estimators: record the first window's iterations
  // σ of the output noise the run declares: its scenario's "noise" when it simulates the data
  // without process noise; 0 for recorded data (--data), whose noise the scenario does not
  // know, and with process noise, which a window (the model exact over N samples) does not
  // account for. A least-squares window checks its answers against σ² I unless its own
  // measurement_covariance is given.
  double output_noise = 0.0;
};

struct ObserverTypeEntry {
  std::string name{};
  std::string description;    // one line, with its reference
  std::string condition;      // what the model must be (for `nlobs list`); empty: any model
  std::vector<KeyInfo> keys;  // every key but "type", "initial" and "model" included
  // Reads the entry's keys but "type", "initial" and "model"; may check them against the
  // model (sizes). Throws std::invalid_argument through JsonReader::fail.
  std::function<std::any(JsonReader& object, const ModelInstance& model)> parse;
  // Writes what parse read, so that parsing it again gives the same observer.
  std::function<void(const std::any& spec, nlohmann::json& out)> write;
  // Throws InvalidInput (options, a model the type cannot take) or std::invalid_argument.
  std::function<std::unique_ptr<Observer>(const std::any& spec, const ObserverBuild& build)> build;
  // Optional: figures a run prints and writes before it starts (an array of objects, summary
  // key "bounds"); warnings are appended.
  std::function<nlohmann::json(const std::any& spec, std::vector<std::string>* warnings)> report;
};

// NamedRegistry refuses an observer type without parse, write or build.
inline std::string missing_part(const ObserverTypeEntry& e) {
  return e.parse && e.write && e.build ? std::string()
                                       : std::string("needs parse, write and build");
}

using ObserverTypeRegistry = NamedRegistry<ObserverTypeEntry>;

// The process-wide registry: the built-in types, then what plugins and user code add.
ObserverTypeRegistry& observer_type_registry();

// An observer type with its own spec type; observer_type_entry() erases it.
template <typename Spec>
struct ObserverTypeDefinition {
  std::string name{};
  std::string description{};
  std::string condition{};
  std::vector<KeyInfo> keys{};
  std::function<Spec(JsonReader& object, const ModelInstance& model)> parse{};
  std::function<void(const Spec& spec, nlohmann::json& out)> write{};
  std::function<std::unique_ptr<Observer>(const Spec& spec, const ObserverBuild& build)> build{};
  std::function<nlohmann::json(const Spec& spec, std::vector<std::string>* warnings)> report{};
};

template <typename Spec>
ObserverTypeEntry observer_type_entry(ObserverTypeDefinition<Spec> d) {
  if (!d.parse || !d.write || !d.build) {
    throw InvalidInput("observer type '" + d.name + "' needs parse, write and build");
  }
  ObserverTypeEntry e{std::move(d.name),
                      std::move(d.description),
                      std::move(d.condition),
                      std::move(d.keys),
                      {},
                      {},
                      {},
                      {}};
  e.parse = [parse = std::move(d.parse)](JsonReader& o, const ModelInstance& m) -> std::any {
    return parse(o, m);
  };
  e.write = [write = std::move(d.write)](const std::any& s, nlohmann::json& out) {
    write(std::any_cast<const Spec&>(s), out);
  };
  e.build = [build = std::move(d.build)](const std::any& s, const ObserverBuild& b) {
    return build(std::any_cast<const Spec&>(s), b);
  };
  if (d.report) {
    e.report = [report = std::move(d.report)](const std::any& s, std::vector<std::string>* w) {
      return report(std::any_cast<const Spec&>(s), w);
    };
  }
  return e;
}

// One entry of a scenario's "observers", parsed.
struct ObserverSpec {
  std::string type;
  std::any spec;                             // the type's own, from its parse
  std::optional<Eigen::VectorXd> initial{};  // "initial"
  std::optional<nlohmann::json> model{};     // "model": the design model's spec
};

// Reads one observer object strictly. `model` is the scenario's (sizes are checked against it).
ObserverSpec parse_observer_spec(JsonReader& object, const ModelInstance& model,
                                 const ObserverTypeRegistry& types = observer_type_registry());
// The object parse_observer_spec reads back to the same observer.
nlohmann::json observer_spec_json(const ObserverSpec& spec,
                                  const ObserverTypeRegistry& types = observer_type_registry());
// The spec with one key set to `value`, read again strictly (sweeps): an error names `where`.
ObserverSpec with_key(const ObserverSpec& spec, const std::string& key, const nlohmann::json& value,
                      const ModelInstance& model, const std::string& where,
                      const ObserverTypeRegistry& types = observer_type_registry());
// Whether the spec's type lists `key`.
bool has_key(const ObserverSpec& spec, const std::string& key,
             const ObserverTypeRegistry& types = observer_type_registry());
// Builds it; `start`, `design` and `output_noise` as in ObserverBuild. InvalidInput from the
// type is prefixed with `where`.
std::unique_ptr<Observer> build_observer(
    const ObserverSpec& spec, const ModelInstance& model, const Eigen::VectorXd& start,
    const std::string& where, bool trace_first_window, double output_noise = 0.0,
    const ObserverTypeRegistry& types = observer_type_registry());

}  // namespace nlobs
