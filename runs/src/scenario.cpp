#include "nlobs/runs/scenario.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

#include "builtin_scenario_texts.hpp"
#include "nlobs/common/invalid_input.hpp"
#include "nlobs/common/printable.hpp"
#include "nlobs/registry/json_reader.hpp"
#include "nlobs/runs/input_file.hpp"
#include "nlobs/runs/measurements_file.hpp"

namespace nlobs {
namespace {

nlohmann::json vector_json(const Eigen::VectorXd& v) {
  return std::vector<double>(v.data(), v.data() + v.size());
}

// A schedule's knots from the file: "times" (t_0 < t_1 < …) and "values", one per time, each one
// number (every input alike) or m numbers (the model's inputs, in order).
void read_knots(JsonReader& in, Eigen::Index inputs, InputSchedule& schedule) {
  if (!in.has("times") || !in.has("values")) in.fail("a schedule needs 'times' and 'values'");
  const Eigen::VectorXd times = *in.vector("times");
  const Eigen::MatrixXd values = *in.matrix("values");  // K × 1 or K × m
  if (values.rows() != times.size()) {
    in.fail("'values' has " + std::to_string(values.rows()) + " entries for " +
            std::to_string(times.size()) +
            " 'times': one per time (one number, or an array of the model's inputs)");
  }
  if (values.cols() != 1 && values.cols() != inputs) {
    in.fail("each entry of 'values' must be one number (every input) or " + std::to_string(inputs) +
            " numbers (the model's inputs), not " + std::to_string(values.cols()));
  }
  schedule.times.assign(times.data(), times.data() + times.size());
  schedule.values = values.transpose().replicate(values.cols() == 1 ? inputs : 1, 1);
}

// The input kinds by family, named once: a signal on every input alike, knots in the file,
// and a schedule (knots in the file or from a CSV file).
bool input_is_signal(const std::string& kind) {
  return kind == "zero" || kind == "constant" || kind == "sin";
}
bool input_has_knots(const std::string& kind) {
  return kind == "piecewise_constant" || kind == "piecewise_linear";
}
bool input_is_schedule(const std::string& kind) {
  return input_has_knots(kind) || kind == "file";
}

InputSpec parse_input(JsonReader& in, const AnyModel& model, const std::string& base_directory) {
  InputSpec spec;
  spec.kind = in.text("kind").value_or("zero");
  if (input_is_signal(spec.kind)) {
    spec.value = in.number("value").value_or(0.0);
    spec.amplitude = in.number("amplitude").value_or(1.0);
    spec.frequency = in.number("frequency").value_or(1.0);
    in.finish({"kind", "value", "amplitude", "frequency"});
    return spec;
  }
  if (!input_is_schedule(spec.kind)) {
    in.fail("'kind' must be zero, constant, sin, piecewise_constant, piecewise_linear or file");
  }
  const Eigen::Index inputs = model.inputs();
  if (inputs == 0) {
    in.fail("'kind' " + spec.kind + ": model '" + printable(model.name()) +
            "' has no input for the schedule to drive");
  }
  if (input_has_knots(spec.kind)) {
    read_knots(in, inputs, spec.schedule);
    spec.schedule.interpolation = spec.kind == "piecewise_linear"
                                      ? InputSchedule::Interpolation::kLinear
                                      : InputSchedule::Interpolation::kPrevious;
    in.finish({"kind", "times", "values"});
  } else {
    const std::string interpolation = in.text("interpolation").value_or("previous");
    if (interpolation != "previous" && interpolation != "linear") {
      in.fail("'interpolation' must be previous or linear");
    }
    const std::string given = in.required_text("file");
    std::filesystem::path path(given);
    if (path.is_relative() && !base_directory.empty()) path = base_directory / path;
    // Written back absolute, so that the scenario.json a run writes reads the same file from
    // anywhere; not normalised ("link/../u.csv" is not "u.csv" when link is a symbolic link);
    // as given when the absolute path is no UTF-8 (JSON holds only UTF-8).
    std::error_code ec;
    const std::filesystem::path absolute = std::filesystem::absolute(path, ec);
    if (!ec) path = absolute;
    spec.file = path.string();
    try {
      (void)nlohmann::json(spec.file).dump();
    } catch (const nlohmann::json::type_error&) {
      spec.file = given;
    }
    in.finish({"kind", "file", "interpolation"});
    Measurements read;
    try {  // t, u1..um: the data file's reader with no output columns
      std::ifstream stream = open_input_file(path.string(), "input file");
      read = parse_measurements_csv(stream, path.string(), 0, inputs);
    } catch (const std::invalid_argument& e) {
      in.fail(e.what());
    }
    spec.schedule.times.assign(read.t.data(), read.t.data() + read.t.size());
    spec.schedule.values = read.u;
    spec.schedule.interpolation = interpolation == "linear"
                                      ? InputSchedule::Interpolation::kLinear
                                      : InputSchedule::Interpolation::kPrevious;
  }
  try {
    spec.schedule.validate(inputs);
  } catch (const InvalidInput& e) {
    in.fail(e.what());
  }
  return spec;
}

nlohmann::json input_json(const InputSpec& in) {
  if (in.kind == "file") {
    return {{"kind", in.kind},
            {"file", in.file},
            {"interpolation", in.schedule.interpolation == InputSchedule::Interpolation::kLinear
                                  ? "linear"
                                  : "previous"}};
  }
  if (input_has_knots(in.kind)) {
    nlohmann::json values = nlohmann::json::array();
    for (Eigen::Index i = 0; i < in.schedule.values.cols(); ++i) {
      values.push_back(vector_json(in.schedule.values.col(i)));
    }
    return {{"kind", in.kind}, {"times", in.schedule.times}, {"values", values}};
  }
  return {{"kind", in.kind},
          {"value", in.value},
          {"amplitude", in.amplitude},
          {"frequency", in.frequency}};
}

}  // namespace

std::vector<std::string> builtin_scenarios() {
  std::vector<std::string> names;
  for (const auto& [name, text] : detail::builtin_scenario_texts()) names.push_back(name);
  return names;
}

Scenario load_scenario(const std::string& name_or_file) {
  const auto& builtins = detail::builtin_scenario_texts();
  if (auto it = builtins.find(name_or_file); it != builtins.end()) {
    // The installed file's text, through the reader a user's file goes through.
    std::istringstream in(it->second);
    return parse_scenario(parse_json(in, "built-in scenario " + it->first),
                          "built-in scenario " + it->first);
  }
  std::error_code ec;
  if (!std::filesystem::exists(name_or_file, ec) && !ec) {  // an error: open_input_file says it
    std::string list;
    for (const auto& s : builtin_scenarios()) list += (list.empty() ? "" : ", ") + s;
    throw std::invalid_argument("'" + name_or_file + "' is neither a built-in scenario (" + list +
                                ") nor a JSON file");
  }
  std::ifstream in = open_input_file(name_or_file, "scenario file");
  return parse_scenario(parse_json(in, name_or_file), name_or_file,
                        std::filesystem::path(name_or_file).parent_path().string());
}

Scenario parse_scenario(const nlohmann::json& json, const std::string& where,
                        const std::string& base_directory) {
  JsonReader r(json, where);
  Scenario s;
  s.name = r.required_text("name");
  if (auto v = r.text("description")) s.description = *v;
  if (!r.has("model")) r.fail("missing field 'model'");
  auto model_spec = r.object("model");
  s.model = model_spec->json();
  // Built now, to validate (naming keys), and kept for the run.
  auto built = std::make_shared<const Scenario::BuiltModel>(
      Scenario::BuiltModel{s.model, make_model_instance(*model_spec)});
  const ModelInstance& instance = built->instance;
  const AnyModel& model = instance.discrete;
  s.x0 = r.required_vector("x0");
  s.initial_guess = r.required_vector("initial_guess");
  // Sizes against the model before the observers are read: a covariance given as one number v
  // becomes v I of the model's size there, which x0's n entries make no larger than the file.
  if (s.x0.size() != model.states() || s.initial_guess.size() != model.states()) {
    r.fail("'x0' and 'initial_guess' must have " + std::to_string(model.states()) +
           " entries (the model's states)");
  }
  if (auto v = r.integer("steps", 1, kMaxScenarioSteps)) s.steps = *v;
  if (auto v = r.number("noise")) {
    if (*v < 0) r.fail("'noise' must be >= 0");
    s.noise = *v;
  }
  if (auto v = r.number("process_noise")) {
    if (*v < 0) r.fail("'process_noise' must be >= 0");
    s.process_noise = *v;
  }
  if (auto v = r.integer("seed", 0, std::numeric_limits<long>::max())) {
    s.seed = static_cast<std::uint64_t>(*v);
  }
  if (auto v = r.number("settle_time")) {
    if (!(*v >= 0.0) || !std::isfinite(*v)) r.fail("'settle_time' must be finite and >= 0 (s)");
    s.settle_time = *v;
  }
  if (auto in = r.object("input")) s.input = parse_input(*in, model, base_directory);
  for (JsonReader& o : r.objects("observers")) {
    s.observers.push_back(parse_observer_spec(o, instance));
  }
  if (s.observers.empty()) r.fail("'observers' must list at least one observer");
  if (auto rep = r.object("reported")) {
    const nlohmann::json& raw = rep->json();
    for (auto it = raw.begin(); it != raw.end(); ++it) {
      auto entry = rep->object(it.key());
      for (const char* key : {"mse", "first_window_iterations"}) {
        if (auto v = entry->number(key)) s.reported[it.key()][key] = *v;
      }
      entry->finish({"mse", "first_window_iterations"});
    }
  }
  r.finish({"name", "description", "model", "x0", "initial_guess", "steps", "noise",
            "process_noise", "seed", "input", "observers", "reported", "settle_time"});
  s.built_model = std::move(built);
  return s;
}

nlohmann::json to_json(const Scenario& s) {
  nlohmann::json j;
  j["name"] = s.name;
  if (!s.description.empty()) j["description"] = s.description;
  j["model"] = s.model;
  j["x0"] = vector_json(s.x0);
  j["initial_guess"] = vector_json(s.initial_guess);
  j["steps"] = s.steps;
  j["noise"] = s.noise;
  if (s.process_noise > 0.0) j["process_noise"] = s.process_noise;
  j["seed"] = s.seed;
  j["input"] = input_json(s.input);
  nlohmann::json observers = nlohmann::json::array();
  for (const ObserverSpec& o : s.observers) observers.push_back(observer_spec_json(o));
  j["observers"] = observers;
  if (!s.reported.empty()) j["reported"] = s.reported;
  if (s.settle_time >= 0.0) j["settle_time"] = s.settle_time;
  return j;
}

ModelInstance scenario_model(const Scenario& s) {
  // The model parse_scenario built, unless the scenario's model has been edited since (a sweep
  // over one of its parameters).
  if (s.built_model && s.built_model->spec == s.model) return s.built_model->instance;
  JsonReader m(s.model, s.name + ".model");
  return make_model_instance(m);
}

Measurements simulate_scenario(const Scenario& s, const AnyModel& model) {
  SimulationOptions sim;
  sim.steps = s.steps;
  sim.noise_std = s.noise;
  sim.process_noise_std = s.process_noise;
  sim.seed = s.seed;
  sim.sample_time = model.sample_time() > 0 ? model.sample_time() : 1.0;
  if (input_is_schedule(s.input.kind)) {  // a scenario built or edited in C++: checked once here
    try {
      s.input.schedule.validate(model.inputs());
    } catch (const InvalidInput& e) {
      throw InvalidInput("scenario '" + s.name + "': " + e.what());
    }
  } else if (!input_is_signal(s.input.kind)) {
    throw InvalidInput("scenario '" + s.name + "': input kind '" + printable(s.input.kind) +
                       "' is none of zero, constant, sin, piecewise_constant, piecewise_linear, "
                       "file");
  }
  sim.input = [&s, &model](long k) { return scenario_input(s, model, k); };
  return simulate(model, s.x0, sim);
}

Eigen::VectorXd scenario_input(const Scenario& s, const AnyModel& model, long k) {
  Eigen::VectorXd u = Eigen::VectorXd::Zero(model.inputs());
  if (u.size() == 0 || s.input.kind == "zero") return u;
  // Inputs are held over a sample.
  const double t = static_cast<double>(k) * model.sample_time();
  if (input_is_schedule(s.input.kind)) {
    const InputSchedule& schedule = s.input.schedule;
    if (schedule.times.empty() || schedule.values.rows() != u.size() ||
        schedule.values.cols() != static_cast<Eigen::Index>(schedule.times.size())) {
      throw InvalidInput("scenario '" + s.name + "': its input schedule is not " +
                         std::to_string(u.size()) + " inputs at one or more knots");
    }
    // A knot within rounding of t_k (k T in floating point) is reached at k.
    return schedule.at(t, 1e-9 * model.sample_time());
  }
  u.setConstant(s.input.kind == "constant" ? s.input.value
                                           : s.input.amplitude * std::sin(s.input.frequency * t));
  return u;
}

std::vector<std::unique_ptr<Observer>> make_observers(const Scenario& s,
                                                      const ModelInstance& instance,
                                                      bool trace_first_window,
                                                      double output_noise) {
  std::vector<std::unique_ptr<Observer>> out;
  for (size_t i = 0; i < s.observers.size(); ++i) {
    const ObserverSpec& o = s.observers[i];
    out.push_back(build_observer(o, instance, o.initial.value_or(s.initial_guess),
                                 s.name + ".observers[" + std::to_string(i) + "]",
                                 trace_first_window, output_noise));
  }
  return out;
}

nlohmann::json observer_reports(const Scenario& s, std::vector<std::string>* warnings) {
  nlohmann::json out = nlohmann::json::array();
  for (size_t i = 0; i < s.observers.size(); ++i) {
    const ObserverSpec& o = s.observers[i];
    const ObserverTypeEntry& entry = observer_type_registry().get(o.type);
    if (!entry.report) continue;
    nlohmann::json items;
    try {  // a user's report hook: anything it throws is named
      items = entry.report(o.spec, warnings);
    } catch (...) {
      throw std::invalid_argument(s.name + ".observers[" + std::to_string(i) +
                                  "]: observer type '" + o.type +
                                  "': its report threw: " + current_exception_text());
    }
    for (auto& item : items) out.push_back(std::move(item));
  }
  return out;
}

}  // namespace nlobs
