#include "nlobs/runs/sweep.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "nlobs/registry/observer_types.hpp"
#include "nlobs/runs/run_metrics.hpp"

namespace nlobs {
namespace {

std::string value_text(double v) {
  std::ostringstream os;
  os << v;  // as %g
  return os.str();
}

// A swept value as the JSON a scenario file would hold: a whole number as an integer, so that
// keys read as integers (an MHE's horizon, an observer's substeps) take it as they take
// `"horizon": 8`; any other number as itself (a key read as a number takes both).
nlohmann::json value_json(double v) {
  constexpr double kExactIntegers = 9007199254740992.0;  // 2^53: every whole double below is exact
  if (v == std::floor(v) && std::abs(v) <= kExactIntegers) return static_cast<std::int64_t>(v);
  return v;
}

}  // namespace

SweepRun run_sweep(const PreparedScenario& prepared, const std::string& key,
                   const std::vector<double>& values, const SweepSettings& settings) {
  const Scenario& s = prepared.scenario;
  const Measurements& data = prepared.data;
  if (values.empty()) throw std::invalid_argument(settings.label + " " + key + ": no values");
  for (const double v : values) {
    if (!std::isfinite(v)) {
      throw std::invalid_argument(settings.label + " " + key + ": the value " + value_text(v) +
                                  " is not finite");
    }
  }
  if (!data.has_truth())
    throw std::invalid_argument(settings.label + " needs simulated data (the truth)");

  SweepRun sweep;
  sweep.key = key;
  const auto takes = [&](const ObserverSpec& o) { return has_key(o, key); };
  sweep.model_parameter = std::none_of(s.observers.begin(), s.observers.end(), takes);
  for (std::size_t i = 0; i < s.observers.size(); ++i) {
    const ObserverSpec& o = s.observers[i];
    const bool given = takes(o) && (key != "sample_period" ||
                                    observer_spec_json(o).value("sample_period", 0.0) > 0.0);
    if (given) sweep.swept.push_back(i);
    if (given || !settings.only_swept_observers || sweep.model_parameter) sweep.run.push_back(i);
  }
  if (!sweep.model_parameter && sweep.swept.empty()) {
    throw std::invalid_argument(settings.label + " " + key +
                                ": no observer of the scenario has it on (sample_period > 0)");
  }
  sweep.settle_index = std::max(prepared.settle_index, 0L);
  if (key == "horizon" && data.steps() > 1) {
    // Every value counts the same samples: those after the longest horizon has filled. A
    // modulating-function observer's horizon is a time T; the MHE's is N samples (full from
    // sample N − 1 on).
    const double delta = data.t[1] - data.t[0];
    const double longest = *std::max_element(values.begin(), values.end());
    double filled = 0.0;
    for (const std::size_t i : sweep.swept) {
      const std::string& type = s.observers[i].type;
      filled = std::max(filled, type == "mhe" ? longest - 1.0 : std::ceil(longest / delta - 1e-9));
    }
    // (At most the data's length: a horizon of 1e300 s is no index.)
    filled = std::min(filled, static_cast<double>(data.steps()));
    sweep.settle_index = std::max(sweep.settle_index, static_cast<long>(filled));
  }

  for (const double value : values) {
    const std::string which = settings.label + " " + key + " = " + value_text(value) + ": ";
    const auto named = [&](auto&& build) {
      try {
        return build();
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(which + e.what());
      }
    };
    Scenario run = s;
    run.observers.clear();
    for (const std::size_t i : sweep.run) run.observers.push_back(s.observers[i]);
    Measurements simulated;
    const Measurements* d = &data;
    const ModelInstance* model = &prepared.model;
    std::optional<ModelInstance> edited;
    if (sweep.model_parameter) {
      // The model spec's own key (its integration sub-steps) where no observer takes the key.
      if (key == "substeps") {
        run.model["substeps"] = value_json(value);
      } else {
        run.model["parameters"][key] = value_json(value);
      }
      edited = named([&] {
        try {
          return scenario_model(run);
        } catch (const std::invalid_argument& e) {
          throw std::invalid_argument(
              std::string(e.what()) +
              " (a sweep key is a key the scenario's observers take — theta, horizon, "
              "sample_period, … — or a parameter of its model)");
        }
      });
      model = &*edited;
      simulated = simulate_scenario(run, edited->discrete);
      if (!simulated.stop_message.empty()) {
        throw std::runtime_error(which + "simulation " + simulated.stop_message);
      }
      d = &simulated;
    } else {
      for (std::size_t j = 0; j < sweep.run.size(); ++j) {
        const std::size_t i = sweep.run[j];
        if (std::find(sweep.swept.begin(), sweep.swept.end(), i) == sweep.swept.end()) continue;
        run.observers[j] = named([&] {
          return with_key(run.observers[j], key, value_json(value), *model,
                          s.name + ".observers[" + std::to_string(i) + "]");
        });
      }
    }
    // The noise the data were simulated with (a model sweep simulates them again), if any.
    const bool simulated_data = d == &simulated || prepared.simulated;
    const double declared_noise = simulated_data && run.process_noise == 0.0 ? run.noise : 0.0;
    auto observers = named([&] { return make_observers(run, *model, false, declared_noise); });
    SweepValue v;
    v.value = value;
    v.result = measure_observers(*d, observers, sweep.settle_index, v.horizon_indices);
    v.figures = observer_figures(*d, v.result, v.horizon_indices);
    sweep.values.push_back(std::move(v));
  }
  return sweep;
}

}  // namespace nlobs
