#include "nlobs/registry/model_registry.hpp"

#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

#include "builtin_models.hpp"
#include "nlobs/common/printable.hpp"

namespace nlobs {

ModelRegistry& model_registry() {
  static ModelRegistry registry = [] {
    ModelRegistry r("model");
    detail::add_builtin_models_a(r);
    detail::add_builtin_models_b(r);
    detail::add_builtin_models_c(r);
    return r;
  }();
  return registry;
}

ModelInstance make_model_instance(JsonReader& spec, const ModelRegistry& registry) {
  const std::string name = spec.required_text("name");
  const ModelEntry* entry = registry.find(name);
  if (!entry) {
    spec.fail("unknown model '" + name + "'; valid models: " + registry.valid_list());
  }
  DiscretizationOptions discretization{.scheme = entry->default_scheme,
                                       .substeps = entry->default_substeps};
  if (auto s = spec.text("scheme")) {
    const std::optional<Scheme> scheme = scheme_from_name(*s);
    if (!scheme) {
      spec.fail("scheme '" + printable(*s) + "' is not one of " + std::string(kSchemeNames));
    }
    discretization.scheme = *scheme;
  }
  if (auto n = spec.integer("substeps", 1, DiscretizationOptions::kMostSubsteps)) {
    discretization.substeps = static_cast<int>(*n);
  }
  if (auto a = spec.number("absolute_tolerance")) discretization.absolute_tolerance = *a;
  if (auto r = spec.number("relative_tolerance")) discretization.relative_tolerance = *r;
  try {
    discretization.validate();
  } catch (const InvalidInput& e) {
    spec.fail(e.what());
  }
  const double step = spec.number("step").value_or(entry->default_step);
  if (!(step > 0.0) || !std::isfinite(step)) spec.fail("'step' must be finite and > 0");
  static const nlohmann::json empty = nlohmann::json::object();
  std::optional<JsonReader> parameters = spec.object("parameters");
  JsonReader p = parameters ? *parameters : JsonReader(empty, spec.where() + ".parameters");
  spec.finish({"absolute_tolerance", "name", "parameters", "relative_tolerance", "scheme", "step",
               "substeps"});
  try {
    return entry->make(p, step, discretization);
  } catch (const InvalidInput& e) {  // the discretisation's refusal of the step
    spec.fail(e.what());
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    if (what.compare(0, spec.where().size(), spec.where()) == 0) throw;  // JsonReader::fail
    spec.fail("model '" + printable(name) + "': " + printable(what));
  } catch (...) {  // an entry of a user's (a plugin's make): anything, named by the model
    spec.fail("model '" + printable(name) + "': its factory threw: " + current_exception_text());
  }
}

}  // namespace nlobs
