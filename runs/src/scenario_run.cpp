#include "nlobs/runs/scenario_run.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "nlobs/runs/measurements_file.hpp"
#include "nlobs/runs/run_metrics.hpp"

namespace nlobs {

nlohmann::json number_or_null(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

namespace {

nlohmann::json vector_or_null(const Eigen::VectorXd& v) {
  nlohmann::json a = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(number_or_null(v[i]));
  return a;
}

void add_modulating_json(const std::optional<ModulatingMetrics>& m, nlohmann::json& o) {
  if (!m) return;
  o["max_eta_rel_error_after_horizon"] = number_or_null(m->rel_after_horizon);
  o["max_eta_error_after_horizon"] = number_or_null(m->abs_after_horizon);
  o["final_eta_rel_error"] = number_or_null(m->final_rel);
  o["eta_rms_after"] = number_or_null(m->eta_rms_after);
  o["max_eta_bound"] = number_or_null(m->max_bound);
}

// The first sample of "after": t >= settle_time on the model's sample grid, at most the data's
// length; −1 without a settle_time.
long settle_index_of(const Scenario& s, const AnyModel& model, Eigen::Index steps) {
  if (s.settle_time < 0.0) return -1;
  const double T = model.sample_time() > 0 ? model.sample_time() : 1.0;
  return static_cast<long>(
      std::min(std::ceil(s.settle_time / T - 1e-9), static_cast<double>(steps)));
}

// Measurements a caller gives, against the model they are for.
void check_data(const Measurements& data, const AnyModel& model, const std::string& source) {
  const auto refuse = [&](const std::string& what) {
    throw std::invalid_argument("the data from " + source + " " + what);
  };
  if (data.y.rows() != model.outputs()) {
    refuse("has " + std::to_string(data.y.rows()) + " outputs where the model has " +
           std::to_string(model.outputs()));
  }
  if (data.t.size() != data.steps()) refuse("has not one time per sample");
  for (Eigen::Index k = 0; k < data.t.size(); ++k) {
    if (!std::isfinite(data.t[k])) {
      refuse("has a time that is not a finite number at sample " + std::to_string(k));
    }
  }
  // (A model without inputs takes u of 0 rows, one column per sample, as a simulation gives.)
  if (data.u.rows() != model.inputs() || data.u.cols() != data.steps()) {
    refuse("has inputs u of " + std::to_string(data.u.rows()) + "x" +
           std::to_string(data.u.cols()) + " where the model's " + std::to_string(model.inputs()) +
           " inputs at " + std::to_string(data.steps()) + " samples need " +
           std::to_string(model.inputs()) + "x" + std::to_string(data.steps()));
  }
  if (data.has_truth() && (data.x.rows() != model.states() || data.x.cols() != data.steps())) {
    refuse("has a true state that is not the model's " + std::to_string(model.states()) +
           " states at every sample");
  }
  if (data.steps() == 0) refuse("has no sample");
}

}  // namespace

nlohmann::json summary_json(const ScenarioRun& run) {
  const Scenario& s = run.prepared.scenario;
  const Measurements& data = run.prepared.data;
  const RunResult& r = run.result;
  const nlohmann::json& bounds = run.observer_reports;
  const std::vector<std::string>& warnings = run.warnings;
  // run_prepared fills the figures; a ScenarioRun put together otherwise gets them here.
  const std::vector<ObserverFigures> computed =
      run.figures.size() == r.metrics.size() ? std::vector<ObserverFigures>()
                                             : observer_figures(data, r, run.horizon_indices);
  const std::vector<ObserverFigures>& figures = computed.empty() ? run.figures : computed;
  nlohmann::json observers = nlohmann::json::array();
  for (const ObserverMetrics& m : r.metrics) {
    nlohmann::json o{{"name", m.name},
                     {"engine", m.engine},
                     {"iterations_mean", m.iterations_mean},
                     {"iterations_max", m.iterations_max},
                     {"first_window_iterations", m.first_window_iterations},
                     {"evaluations_mean", m.evaluations_mean},
                     {"ns_per_step", m.ns_per_step},
                     {"failures", m.failures}};
    if (data.has_truth()) {
      o["mse"] = vector_or_null(m.mse);
      o["mse_after_window"] = vector_or_null(m.mse_after_window);
      o["max_error_after"] = vector_or_null(m.max_error_after);
    }
    if (!m.first_failure.empty()) o["first_failure"] = m.first_failure;
    const ObserverFigures& f = figures[observers.size()];
    if (data.has_truth()) {
      const long k = f.time_index_below_1e3;
      o["time_to_1e-3"] = k >= 0 ? nlohmann::json(data.t[k]) : nlohmann::json(nullptr);
    }
    if (f.max_beta_residual) o["max_beta_residual"] = *f.max_beta_residual;
    if (const auto& em = f.embedded) {
      o["max_zhat_norm"] = number_or_null(em->max_zhat_norm);
      o["time_to_z_1e-6"] = em->time_index_below >= 0 ? nlohmann::json(data.t[em->time_index_below])
                                                      : nlohmann::json(nullptr);
      o["final_z_error"] = number_or_null(em->final_z_error);
      o["z_rms_after"] = number_or_null(em->z_rms_after);
      o["max_projection_residual_after"] = number_or_null(em->max_residual_after);
      o["projection_jumps"] = em->jumps;
    }
    add_modulating_json(f.modulating, o);
    observers.push_back(o);
  }
  nlohmann::json j{{"scenario", s.name},           {"steps", data.steps()},
                   {"noise_std", s.noise},         {"seed", s.seed},
                   {"observers", observers},       {"settle_index", r.settle_index},
                   {"source", run.prepared.source}};
  if (!data.stop_message.empty()) j["stop_message"] = data.stop_message;
  if (s.settle_time >= 0.0) j["settle_time"] = s.settle_time;
  if (s.process_noise > 0.0) j["process_noise_std"] = s.process_noise;
  if (!bounds.empty()) j["pi_bounds"] = bounds;
  if (!warnings.empty()) j["warnings"] = warnings;
  return j;
}

PreparedScenario prepare_scenario(Scenario scenario, RunSettings settings) {
  ModelInstance instance = scenario_model(scenario);
  const AnyModel& model = instance.discrete;
  Measurements data;
  std::string source = "simulation";
  if (settings.data) {
    check_data(*settings.data, model, settings.data_source);
    data = std::move(*settings.data);  // (settings is the caller's copy, or moved in)
    source = std::move(settings.data_source);
  } else {
    data = simulate_scenario(scenario, model);  // no sample at all: run_prepared refuses it
  }
  const long settle_index = settle_index_of(scenario, model, data.steps());
  const bool simulated = !settings.data;
  return PreparedScenario{std::move(scenario), std::move(instance), std::move(data),
                          std::move(source),   settle_index,        simulated};
}

ScenarioRun run_prepared(PreparedScenario prepared, const RunSettings& settings) {
  if (prepared.data.steps() == 0) {
    throw std::runtime_error("the simulation produced no samples" +
                             (prepared.data.stop_message.empty()
                                  ? std::string()
                                  : " (" + prepared.data.stop_message + ")"));
  }
  ScenarioRun run{std::move(prepared), {}, nlohmann::json::array(), {}, {}, {}};
  const Scenario& s = run.prepared.scenario;
  const Measurements& data = run.prepared.data;
  auto observers = make_observers(s, run.prepared.model, settings.trace_first_window,
                                  run.prepared.simulated && s.process_noise == 0.0 ? s.noise : 0.0);
  Eigen::Index longest = 1;
  for (const auto& o : observers) longest = std::max(longest, o->info().window);
  if (longest > data.steps()) {
    std::ostringstream os;
    os << "a window of " << longest << " samples is longer than the data (" << data.steps()
       << " samples)";
    throw std::invalid_argument(os.str());
  }
  // A warning the run found (once: the observers' own were reported before it).
  const auto warn = [&](const std::string& w) {
    if (std::find(run.warnings.begin(), run.warnings.end(), w) != run.warnings.end()) return;
    run.warnings.push_back(w);
    if (settings.warning) settings.warning(w);
  };
  run.observer_reports = observer_reports(s, &run.warnings);
  for (const auto& o : observers) {
    for (const auto& w : o->info().warnings) run.warnings.push_back(w);
  }
  if (settings.warning) {
    for (const auto& w : run.warnings) settings.warning(w);
  }
  run.result = measure_observers(data, observers, run.prepared.settle_index, run.horizon_indices,
                                 settings.progress);
  run.figures = observer_figures(data, run.result, run.horizon_indices);
  // What the run itself found (a window map that does not contract, a singular guess).
  for (const auto& o : observers) {
    for (const auto& w : o->info().warnings) warn(w);
  }
  return run;
}

namespace {

// The data, if any, moves into the prepared scenario; the callbacks stay for the run.
RunSettings data_part(RunSettings& settings) {
  RunSettings prepare;
  prepare.data = std::move(settings.data);
  prepare.data_source = settings.data_source;
  settings.data.reset();
  return prepare;
}

}  // namespace

ScenarioRun run_scenario(Scenario scenario, RunSettings settings) {
  RunSettings prepare = data_part(settings);
  return run_prepared(prepare_scenario(std::move(scenario), std::move(prepare)), settings);
}

PreparedScenario prepare_request(const ScenarioRequest& request, RunSettings settings) {
  Scenario s = load_scenario(request.scenario);
  if (request.steps) {
    if (*request.steps < 1 || *request.steps > kMaxScenarioSteps) {
      throw std::invalid_argument("'steps' = " + std::to_string(*request.steps) +
                                  " is out of range: must be in 1.." +
                                  std::to_string(kMaxScenarioSteps));
    }
    s.steps = *request.steps;
  }
  if (request.noise) {
    if (!(*request.noise >= 0.0) || !std::isfinite(*request.noise)) {
      std::ostringstream os;
      os << "'noise' = " << *request.noise << " is not a finite number >= 0";
      throw std::invalid_argument(os.str());
    }
    s.noise = *request.noise;
  }
  if (request.seed) s.seed = *request.seed;
  if (!request.data_file.empty() && settings.data) {
    throw std::invalid_argument("'data_file' = " + request.data_file +
                                ": measurements were given as well (RunSettings::data); give "
                                "one of them");
  }
  if (request.data_file.empty() && request.allow_late) {
    throw std::invalid_argument(
        "'allow_late' applies to a data file ('data_file'): a simulation's times always increase");
  }
  if (settings.parsed) settings.parsed(s);
  if (!request.data_file.empty()) {
    const AnyModel model = scenario_model(s).discrete;  // the scenario's own, not built again
    settings.data = read_measurements_csv(request.data_file, model.outputs(), model.inputs(),
                                          request.allow_late);
    settings.data_source = request.data_file;
  }
  return prepare_scenario(std::move(s), std::move(settings));
}

ScenarioRun run_request(const ScenarioRequest& request, RunSettings settings) {
  RunSettings prepare = data_part(settings);
  prepare.parsed = settings.parsed;
  PreparedScenario prepared = prepare_request(request, std::move(prepare));
  if (settings.prepared) settings.prepared(prepared);
  return run_prepared(std::move(prepared), settings);
}

}  // namespace nlobs
