#include "nlobs/registry/observer_types.hpp"

#include <algorithm>
#include <any>
#include <stdexcept>
#include <string>

#include "nlobs/common/printable.hpp"
#include "observer_types/builtin_observer_types.hpp"

namespace nlobs {
namespace {

bool lists(const ObserverTypeEntry& e, const std::string& key) {
  return std::any_of(e.keys.begin(), e.keys.end(), [&](const KeyInfo& k) { return k.key == key; });
}

// A spec parsed by one registry's entry and written or built by another's of the same name.
InvalidInput mismatched(const std::string& type) {
  return InvalidInput("observer type '" + type +
                      "': its spec was parsed by another registry's entry of that name");
}

}  // namespace

ObserverTypeRegistry& observer_type_registry() {
  static ObserverTypeRegistry registry = [] {
    ObserverTypeRegistry r("observer type");
    detail::add_builtin_observer_types(r);
    return r;
  }();
  return registry;
}

ObserverSpec parse_observer_spec(JsonReader& o, const ModelInstance& model,
                                 const ObserverTypeRegistry& types) {
  ObserverSpec spec;
  spec.type = o.required_text("type");
  const ObserverTypeEntry* entry = types.find(spec.type);
  if (!entry) {
    o.fail("unknown observer type '" + spec.type + "'; valid: " + types.valid_list());
  }
  try {
    spec.spec = entry->parse(o, model);
  } catch (const InvalidInput& e) {  // thrown by the entry itself, not through o.fail: add where
    o.fail(e.what());
  } catch (const std::invalid_argument&) {  // o.fail (where included), as documented
    throw;
  } catch (...) {  // a user's parse hook: anything, named by the type
    o.fail("observer type '" + spec.type + "': its parse threw: " + current_exception_text());
  }
  if (lists(*entry, "initial")) spec.initial = o.vector("initial");
  if (lists(*entry, "model")) {
    // The observer's own model: built now (errors name its keys), sizes checked against ours.
    if (auto design = o.object("model")) {
      const AnyModel own = make_model_instance(*design).discrete;
      const AnyModel& m = model.discrete;
      if (own.states() != m.states() || own.outputs() != m.outputs() ||
          own.inputs() != m.inputs() || own.sample_time() != m.sample_time()) {
        o.fail("'model' must have the scenario model's sizes and sample time");
      }
      spec.model = design->json();
    }
  }
  std::vector<std::string> keys{"type"};
  for (const KeyInfo& k : entry->keys) keys.push_back(k.key);
  o.finish(keys);
  return spec;
}

nlohmann::json observer_spec_json(const ObserverSpec& spec, const ObserverTypeRegistry& types) {
  nlohmann::json out{{"type", spec.type}};
  try {
    types.get(spec.type).write(spec.spec, out);
  } catch (const std::bad_any_cast&) {
    throw mismatched(spec.type);
  } catch (...) {  // a user's write hook
    throw InvalidInput("observer type '" + spec.type +
                       "': its write threw: " + current_exception_text());
  }
  if (spec.initial) {
    out["initial"] =
        std::vector<double>(spec.initial->data(), spec.initial->data() + spec.initial->size());
  }
  if (spec.model) out["model"] = *spec.model;
  return out;
}

ObserverSpec with_key(const ObserverSpec& spec, const std::string& key, const nlohmann::json& value,
                      const ModelInstance& model, const std::string& where,
                      const ObserverTypeRegistry& types) {
  nlohmann::json j = observer_spec_json(spec, types);
  j[key] = value;
  JsonReader reader(j, where);
  return parse_observer_spec(reader, model, types);
}

bool has_key(const ObserverSpec& spec, const std::string& key, const ObserverTypeRegistry& types) {
  const ObserverTypeEntry* e = types.find(spec.type);
  return e && lists(*e, key);
}

std::unique_ptr<Observer> build_observer(const ObserverSpec& spec, const ModelInstance& model,
                                         const Eigen::VectorXd& start, const std::string& where,
                                         bool trace_first_window, double output_noise,
                                         const ObserverTypeRegistry& types) {
  const ObserverTypeEntry& entry = types.get(spec.type);
  std::optional<ModelInstance> design;
  if (spec.model) {
    JsonReader reader(*spec.model, where + ".model");
    design = make_model_instance(reader);
  }
  const ObserverBuild build{
      model,       design ? design->discrete : model.discrete, start, where, trace_first_window,
      output_noise};
  std::unique_ptr<Observer> observer;
  try {
    observer = entry.build(spec.spec, build);
  } catch (const std::bad_any_cast&) {
    throw std::invalid_argument(where + ": " + mismatched(spec.type).what());
  } catch (const std::invalid_argument& e) {
    // InvalidInput from the library, or a user's std::invalid_argument: add where once.
    const std::string what = e.what();
    if (what.compare(0, where.size(), where) == 0) throw;
    throw std::invalid_argument(where + ": " + what);
  } catch (...) {  // a user's build hook (or the model code it runs): anything, named
    throw std::invalid_argument(where + ": observer type '" + spec.type +
                                "': its build threw: " + current_exception_text());
  }
  if (!observer) {
    throw std::invalid_argument(where + ": observer type '" + spec.type + "' built no observer");
  }
  // What a report names when a step of this observer throws (run_observers).
  observer->set_model_name(design ? design->name : model.name);
  return observer;
}

}  // namespace nlobs
