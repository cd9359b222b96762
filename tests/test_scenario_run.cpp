// The run layer (nlobs/runs/): a scenario parsed, prepared and run below the CLI. Its model is
// built once (a model nlobs does not ship counts its builds); recorded data of the wrong shape is
// refused naming what is wrong; warnings arrive once and in order; a run's result holds the
// metrics summary.json reports; a ScenarioRequest (name or file, overrides, a data file that
// may be a link or a FIFO) is the scenario as edited by hand, its bad values named; and `nlobs
// run` (the CLI) reports what the library returns.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <Eigen/Core>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "cli_test_files.hpp"
#include "nlobs/registry/register_model.hpp"
#include "nlobs/runs/scenario_run.hpp"
#include "nlobs/runs/sweep.hpp"

namespace nlobs {
namespace {

// x' = −a x + u-free, y = x: a decay nlobs does not ship.
struct Decay : ModelSizes<1, 0, 1> {
  double a = 0.5;
  template <typename T>
  State<T> vector_field(const State<T>& x, const Input&, double) const {
    return State<T>(-a * x[0]);
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return x.template head<1>();
  }
};

std::atomic<int> decay_builds{0};

void register_counted_decay() {
  static const bool done = [] {
    ModelEntry entry = model_entry(ModelDefinition<Decay>{
        .name = "counted-decay",
        .description = "x' = -a x, y = x; counts its builds (test_scenario_run)",
        .parameters = {{"a", "decay rate", [](Decay& m) -> double& { return m.a; }}}});
    entry.make = [inner = entry.make](JsonReader& parameters, double step,
                                      const DiscretizationOptions& discretization) {
      ++decay_builds;
      return inner(parameters, step, discretization);
    };
    model_registry().add(entry, "test_scenario_run");
    return true;
  }();
  (void)done;
}

nlohmann::json decay_scenario() {
  return {{"name", "decay-test"},
          {"model", {{"name", "counted-decay"}, {"parameters", {{"a", 0.5}}}, {"step", 0.01}}},
          {"x0", {2.0}},
          {"initial_guess", {1.0}},
          {"steps", 300},
          {"noise", 0.001},
          {"observers",
           {{{"type", "ekf"},
             {"process_covariance", {{1e-8}}},
             {"measurement_covariance", {{1e-6}}},
             {"initial_covariance", {{1.0}}}},
            {{"type", "luenberger"}, {"gain", {0.3}}}}}};
}

TEST(ScenarioRun, TheModelIsBuiltOnceFromParseToResult) {
  register_counted_decay();
  const int before = decay_builds;
  const Scenario s = parse_scenario(decay_scenario(), "decay-test");
  EXPECT_EQ(decay_builds - before, 1);
  const ScenarioRun run = run_scenario(s);
  EXPECT_EQ(decay_builds - before, 1) << "the run built the model again";
  ASSERT_EQ(run.result.metrics.size(), 2u);
  EXPECT_LT(run.result.metrics[0].mse_after_window[0], 1e-4);  // the EKF tracks the decay

  // A scenario whose model was edited since it was parsed builds the edited one.
  Scenario edited = s;
  edited.model["parameters"]["a"] = 2.0;
  const ScenarioRun faster = run_scenario(edited);
  EXPECT_EQ(decay_builds - before, 2);
  // x(t) = 2 e^{-a t}: the truth at the last sample says which a was simulated.
  const double t = faster.prepared.data.t[299];
  EXPECT_NEAR(faster.prepared.data.x(0, 299), 2.0 * std::exp(-2.0 * t), 1e-6);
}

// The model spec's "substeps" reaches the simulated plant and the observers: forward Euler on
// x' = −a x with s sub-steps per sample of h gives x_k = x0 (1 − a h / s)^{s k} exactly, and a
// bad value is refused at parse time naming the key.
TEST(ScenarioRun, TheModelsSubstepsReachThePlantAndTheObservers) {
  register_counted_decay();
  for (const int substeps : {1, 7}) {
    nlohmann::json spec = decay_scenario();
    spec["model"]["scheme"] = "euler";
    spec["model"]["parameters"]["a"] = 20.0;  // a h = 0.2
    spec["model"]["substeps"] = substeps;
    const ScenarioRun run = run_scenario(parse_scenario(spec, "decay-test"));
    const double per_sample = std::pow(1.0 - 0.2 / substeps, substeps);
    EXPECT_NEAR(run.prepared.data.x(0, 10), 2.0 * std::pow(per_sample, 10), 1e-12) << substeps;
    // The EKF on the same sub-steps: ~1e-8; one that dropped them would be ~7e-5 off.
    EXPECT_LT(run.result.metrics[0].mse_after_window[0], 1e-6) << substeps;
  }
  nlohmann::json bad = decay_scenario();
  bad["model"]["substeps"] = 0;
  try {
    parse_scenario(bad, "decay-test");
    ADD_FAILURE() << "substeps 0 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'substeps' = 0 is out of range: must be in 1..1000"),
              std::string::npos)
        << e.what();
  }
}

// The model spec's "scheme" dopri5 and sdirk3 reach the plant: on x' = −a x (a h = 0.2) the
// truth at sample 10 is that of Discretized on the same scheme, bit for bit (sdirk3's is 1e-4
// below 2 e^{−2}, rk4's 8.5e-6 above: a scheme dropped on the way would show), and the EKF on the
// model follows it.
TEST(ScenarioRun, TheAdaptiveAndImplicitSchemesReachThePlantAndTheObservers) {
  register_counted_decay();
  for (const auto& [name, scheme] :
       {std::pair{"dopri5", Scheme::kDopri5}, {"sdirk3", Scheme::kSdirk3}}) {
    nlohmann::json spec = decay_scenario();
    spec["model"]["scheme"] = name;
    spec["model"]["parameters"]["a"] = 20.0;
    const ScenarioRun run = run_scenario(parse_scenario(spec, "decay-test"));
    Decay decay;
    decay.a = 20.0;
    const Discretized<Decay> same(decay, 0.01, {.scheme = scheme});
    Eigen::Matrix<double, 1, 1> x(2.0);
    for (long k = 0; k < 10; ++k) x = same.f(x, {}, k);
    EXPECT_EQ(run.prepared.data.x(0, 10), x[0]) << name;
    EXPECT_LT(run.result.metrics[0].mse_after_window[0], 1e-6) << name;
  }
}

TEST(ScenarioRun, RecordedDataOfTheWrongShapeIsRefusedNamingIt) {
  register_counted_decay();
  const Scenario s = parse_scenario(decay_scenario(), "decay-test");
  const auto error_of = [&](const Measurements& data) -> std::string {
    try {
      run_scenario(s, {.data = data, .data_source = "mine.csv"});
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "<no error>";
  };
  Measurements two_outputs;
  two_outputs.y = Eigen::MatrixXd::Zero(2, 10);
  two_outputs.u = Eigen::MatrixXd::Zero(0, 10);
  two_outputs.t = Eigen::VectorXd::LinSpaced(10, 0.0, 0.09);
  EXPECT_EQ(error_of(two_outputs), "the data from mine.csv has 2 outputs where the model has 1");
  Measurements no_times;
  no_times.y = Eigen::MatrixXd::Zero(1, 10);
  no_times.u = Eigen::MatrixXd::Zero(0, 10);
  EXPECT_EQ(error_of(no_times), "the data from mine.csv has not one time per sample");
  Measurements nan_time = no_times;
  nan_time.t = Eigen::VectorXd::LinSpaced(10, 0.0, 0.09);
  nan_time.t[4] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(error_of(nan_time),
            "the data from mine.csv has a time that is not a finite number at sample 4");
  Measurements empty;
  empty.y = Eigen::MatrixXd::Zero(1, 0);
  EXPECT_EQ(error_of(empty), "the data from mine.csv has no sample");
  Measurements wrong_truth = two_outputs;
  wrong_truth.y = Eigen::MatrixXd::Zero(1, 10);
  wrong_truth.x = Eigen::MatrixXd::Zero(3, 10);
  EXPECT_EQ(error_of(wrong_truth),
            "the data from mine.csv has a true state that is not the model's 1 states at every "
            "sample");

  // Recorded data of the right shape, one output missing (NaN) and a huge value: a run, not a
  // crash; no truth, so no error metrics.
  Measurements no_input_columns;  // u must have one (empty) column per sample, as simulate gives
  no_input_columns.y = Eigen::MatrixXd::Zero(1, 10);
  no_input_columns.t = Eigen::VectorXd::LinSpaced(10, 0.0, 0.09);
  EXPECT_EQ(error_of(no_input_columns),
            "the data from mine.csv has inputs u of 0x0 where the model's 0 inputs at 10 samples "
            "need 0x10");

  Measurements recorded;
  recorded.t = Eigen::VectorXd::LinSpaced(50, 0.0, 0.49);
  recorded.u = Eigen::MatrixXd::Zero(0, 50);
  recorded.y = (2.0 * (-0.5 * recorded.t.array()).exp()).matrix().transpose();
  recorded.y(0, 7) = std::numeric_limits<double>::quiet_NaN();
  recorded.y(0, 20) = 1e300;
  const ScenarioRun run = run_scenario(s, {.data = recorded, .data_source = "mine.csv"});
  EXPECT_EQ(run.prepared.source, "mine.csv");
  EXPECT_EQ(run.result.estimates[0].cols(), 50);
  const nlohmann::json summary = summary_json(run);
  EXPECT_EQ(summary["source"], "mine.csv");
  EXPECT_FALSE(summary["observers"][0].contains("mse"));
}

TEST(ScenarioRun, ASimulationWithoutASampleIsRefusedWithItsStopMessage) {
  // The lander's mass x3 starts below zero: the model leaves its domain at the first sample.
  nlohmann::json j = to_json(load_scenario("pi-lander"));
  j["x0"][2] = -1.0;
  const Scenario s = parse_scenario(j, "pi-lander, no mass");
  const PreparedScenario prepared = prepare_scenario(s);
  EXPECT_EQ(prepared.data.steps(), 0);
  ASSERT_FALSE(prepared.data.stop_message.empty());
  try {
    run_prepared(prepared);
    FAIL() << "ran";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("the simulation produced no samples"), std::string::npos) << what;
    EXPECT_NE(what.find(prepared.data.stop_message), std::string::npos) << what;
  }
}

TEST(ScenarioRun, AWindowLongerThanTheDataIsRefusedBeforeTheRun) {
  Scenario s = load_scenario("chua-fp");
  s.steps = 4;  // ceres' window holds 6 samples
  try {
    run_scenario(s);
    FAIL() << "ran";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("window of 6 samples is longer than the data (4"),
              std::string::npos)
        << e.what();
  }
}

TEST(ScenarioRun, TheResultHoldsWhatSummaryJsonReports) {
  Scenario s = load_scenario("chua-fp");
  s.steps = 80;
  std::vector<std::string> warned;
  long last_done = 0, calls = 0;
  const ScenarioRun run =
      run_scenario(s, {.progress = [&](long done, long) { last_done = done, ++calls; },
                       .warning = [&](const std::string& w) { warned.push_back(w); }});
  EXPECT_EQ(warned, run.warnings);  // each once, in the order kept
  EXPECT_GT(calls, 0);
  EXPECT_EQ(last_done, 80 * static_cast<long>(s.observers.size()));
  const nlohmann::json j = summary_json(run);
  EXPECT_EQ(j["scenario"], "chua-fp");
  EXPECT_EQ(j["steps"], 80);
  EXPECT_EQ(j["source"], "simulation");
  ASSERT_EQ(j["observers"].size(), s.observers.size());
  for (std::size_t i = 0; i < s.observers.size(); ++i) {
    const nlohmann::json& o = j["observers"][i];
    EXPECT_EQ(o["name"], run.result.metrics[i].name);
    ASSERT_EQ(o["mse"].size(), 3u);
    for (Eigen::Index c = 0; c < 3; ++c) {
      const double mse = run.result.metrics[i].mse[c];
      if (std::isfinite(mse)) {
        EXPECT_EQ(o["mse"][c].get<double>(), mse);
      } else {
        EXPECT_TRUE(o["mse"][c].is_null());
      }
    }
  }
  // The horizon index is each observer's window less one: ceres' window holds 6 samples; the
  // Luenberger observer has none (window 0), so −1 (the metrics read it as 0).
  ASSERT_EQ(run.horizon_indices.size(), s.observers.size());
  EXPECT_EQ(run.result.metrics[5].name, "window:ceres,N=6");
  EXPECT_EQ(run.horizon_indices[5], 5);
  EXPECT_EQ(run.result.metrics[6].name, "luenberger");
  EXPECT_EQ(run.horizon_indices[6], -1);
}

// Some observer of the built-in scenario `name`, run for `steps` samples, reports `key`.
bool some_observer_reports(const std::string& name, long steps, const std::string& key) {
  Scenario s = load_scenario(name);
  s.steps = steps;
  const nlohmann::json summary = summary_json(run_scenario(s));
  for (const auto& o : summary["observers"]) {
    if (o.contains(key)) return true;
  }
  return false;
}

TEST(ScenarioRun, EmbeddedAndCanonicalMetricsComeWithTheObserversThatPublishThem) {
  EXPECT_TRUE(some_observer_reports("hg-duffing", 2000, "max_zhat_norm"));
  EXPECT_TRUE(some_observer_reports("mf-lti", 801, "max_eta_rel_error_after_horizon"));
  EXPECT_FALSE(some_observer_reports("chua-fp", 60, "max_zhat_norm"));  // no high-gain observer
}

// The papers' figures are computed once, into ScenarioRun::figures, and summary.json (like
// `nlobs run`'s tables) reads them: one per observer, the same numbers.
TEST(ScenarioRun, TheFiguresAreComputedOnceAndSummaryJsonReadsThem) {
  for (const auto& [name, steps] : {std::pair<std::string, long>{"hg-duffing", 2000},
                                    std::pair<std::string, long>{"mf-lti", 801},
                                    std::pair<std::string, long>{"mvt-chaotic", 400}}) {
    SCOPED_TRACE(name);
    Scenario s = load_scenario(name);
    s.steps = steps;
    const ScenarioRun run = run_scenario(s);
    ASSERT_EQ(run.figures.size(), run.result.metrics.size());
    const nlohmann::json j = summary_json(run);
    bool any = false;
    for (std::size_t i = 0; i < run.figures.size(); ++i) {
      const ObserverFigures& f = run.figures[i];
      const nlohmann::json& o = j["observers"][i];
      if (f.time_index_below_1e3 >= 0) {
        EXPECT_EQ(o["time_to_1e-3"].get<double>(), run.prepared.data.t[f.time_index_below_1e3]);
      } else {
        EXPECT_TRUE(o["time_to_1e-3"].is_null());
      }
      EXPECT_EQ(o.contains("max_beta_residual"), f.max_beta_residual.has_value());
      EXPECT_EQ(o.contains("max_zhat_norm"), f.embedded.has_value());
      EXPECT_EQ(o.contains("eta_rms_after"), f.modulating.has_value());
      if (f.embedded && std::isfinite(f.embedded->max_zhat_norm)) {
        EXPECT_EQ(o["max_zhat_norm"].get<double>(), f.embedded->max_zhat_norm);
      }
      any |= f.max_beta_residual || f.embedded || f.modulating;
    }
    EXPECT_TRUE(any);  // each scenario has an observer the figures are for
  }
}

TEST(ScenarioRun, BuiltInScenariosAreTheirDataFilesReadAsAUsersFile) {
  // Each built-in is runs/scenarios/NAME.json: its name inside is its file's, and the same file
  // given by path reads to the same scenario.
  const std::vector<std::string> names = builtin_scenarios();
  ASSERT_EQ(names.size(), 13u);
  for (const std::string& name : names) {
    const Scenario builtin = load_scenario(name);
    EXPECT_EQ(builtin.name, name);
    EXPECT_FALSE(builtin.description.empty()) << name;
    const Scenario file = load_scenario(std::string(NLOBS_SCENARIO_DIR) + "/" + name + ".json");
    EXPECT_EQ(to_json(file), to_json(builtin)) << name;
  }
}

TEST(Sweep, AnyObserverKeyIsSweptOnTheSameData) {
  // The sliding-mode observer's gamma: a key no sweep knew by name before (chua-fp).
  Scenario s = load_scenario("chua-fp");
  s.steps = 60;
  const PreparedScenario prepared = prepare_scenario(s);
  const SweepRun sweep = run_sweep(prepared, "gamma", {5.0, 20.0});
  EXPECT_FALSE(sweep.model_parameter);
  ASSERT_EQ(sweep.swept.size(), 1u);
  EXPECT_EQ(s.observers[sweep.swept[0]].type, "sliding_mode");
  EXPECT_EQ(sweep.run.size(), s.observers.size());  // every observer runs
  ASSERT_EQ(sweep.values.size(), 2u);
  const std::size_t smo = sweep.swept[0];
  // Only the swept observer's result depends on the value.
  const RunResult& a = sweep.values[0].result;
  const RunResult& b = sweep.values[1].result;
  EXPECT_NE(a.metrics[smo].mse[0], b.metrics[smo].mse[0]);
  EXPECT_EQ(a.metrics[0].mse[0], b.metrics[0].mse[0]);  // window:picard, untouched
  // Only the swept ones, when asked.
  const SweepRun only = run_sweep(prepared, "gamma", {5.0}, {.only_swept_observers = true});
  ASSERT_EQ(only.values[0].result.metrics.size(), 1u);
  EXPECT_EQ(only.values[0].result.metrics[0].mse[0], a.metrics[smo].mse[0]);
}

// Each value of a sweep carries the papers' figures of its own run, computed with it (the CLI's
// sweep tables read them): the high-gain peaking grows as θ shrinks ([HG-EMB23]), and the
// canonical errors follow the modulating horizon.
TEST(Sweep, EachValueCarriesTheFiguresOfItsRun) {
  const auto same = [](double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); };
  Scenario hg = load_scenario("hg-duffing");
  hg.steps = 2000;
  const SweepRun theta =
      run_sweep(prepare_scenario(hg), "theta", {0.05, 0.1}, {.only_swept_observers = true});
  ASSERT_EQ(theta.values.size(), 2u);
  for (const SweepValue& v : theta.values) {
    ASSERT_EQ(v.figures.size(), v.result.metrics.size());
    ASSERT_TRUE(v.figures[0].embedded.has_value());
    const std::optional<EmbeddedMetrics> again = embedded_metrics(v.result, 0);
    ASSERT_TRUE(again.has_value());
    EXPECT_TRUE(same(v.figures[0].embedded->max_zhat_norm, again->max_zhat_norm));
    EXPECT_TRUE(same(v.figures[0].embedded->z_rms_after, again->z_rms_after));
  }
  EXPECT_GT(theta.values[0].figures[0].embedded->max_zhat_norm,
            theta.values[1].figures[0].embedded->max_zhat_norm);

  Scenario mf = load_scenario("mf-lti");
  mf.steps = 801;
  const SweepRun horizon = run_sweep(prepare_scenario(mf), "horizon", {0.5, 1.0});
  bool any = false;
  for (const SweepValue& v : horizon.values) {
    ASSERT_EQ(v.figures.size(), v.result.metrics.size());
    for (std::size_t i = 0; i < v.figures.size(); ++i) {
      const std::optional<ModulatingMetrics> again =
          modulating_metrics(v.result, i, v.horizon_indices[i]);
      ASSERT_EQ(v.figures[i].modulating.has_value(), again.has_value()) << i;
      if (!again) continue;
      any = true;
      EXPECT_TRUE(same(v.figures[i].modulating->final_rel, again->final_rel));
      EXPECT_TRUE(same(v.figures[i].modulating->max_bound, again->max_bound));
    }
  }
  EXPECT_TRUE(any);  // mf-lti has modulating observers
}

TEST(Sweep, AModelParameterIsSimulatedAgainPerValue) {
  register_counted_decay();
  const PreparedScenario prepared =
      prepare_scenario(parse_scenario(decay_scenario(), "decay-test"));
  const SweepRun sweep = run_sweep(prepared, "a", {0.5, 2.0});
  EXPECT_TRUE(sweep.model_parameter);
  EXPECT_TRUE(sweep.swept.empty());
  ASSERT_EQ(sweep.values.size(), 2u);
  // The faster decay is tracked from an initial error that vanishes sooner: lower MSE.
  EXPECT_LT(sweep.values[1].result.metrics[0].mse[0], sweep.values[0].result.metrics[0].mse[0]);
  // Each value's figures are read against its own simulation, not the prepared one: the same
  // as a run of the scenario with that parameter (a user's model, which nlobs does not ship).
  Scenario faster = prepared.scenario;
  faster.model["parameters"]["a"] = 2.0;
  const ScenarioRun alone = run_scenario(faster);
  ASSERT_EQ(sweep.values[1].figures.size(), alone.figures.size());
  bool settles = false;
  for (std::size_t i = 0; i < alone.figures.size(); ++i) {
    EXPECT_EQ(sweep.values[1].figures[i].time_index_below_1e3,
              alone.figures[i].time_index_below_1e3)
        << i;
    settles |= alone.figures[i].time_index_below_1e3 >= 0;
  }
  EXPECT_TRUE(settles);  // a figure that tells the two simulations apart
}

// What a sweep refuses, as its message; "<no error>" when it runs.
std::string sweep_error(const PreparedScenario& prepared, const std::string& key,
                        const std::vector<double>& values) {
  try {
    run_sweep(prepared, key, values);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "<no error>";
}

// A key read as an integer (the MHE's horizon) takes whole values, as the scenario file's
// `"horizon": 8` is taken; 4.5 is refused naming the key.
TEST(Sweep, AnIntegerKeyTakesWholeValues) {
  register_counted_decay();
  nlohmann::json spec = decay_scenario();
  spec["observers"] = {{{"type", "mhe"},
                        {"horizon", 5},
                        {"process_covariance", {{1e-8}}},
                        {"measurement_covariance", {{1e-6}}},
                        {"initial_covariance", {{1.0}}}}};
  const PreparedScenario prepared = prepare_scenario(parse_scenario(spec, "decay-test"));
  const SweepRun sweep = run_sweep(prepared, "horizon", {4.0, 8.0});
  ASSERT_EQ(sweep.values.size(), 2u);
  // "After" is after the longest horizon has filled: sample 7, not 8 / T = 800 samples (the
  // modulating observers' horizon is a time).
  EXPECT_EQ(sweep.settle_index, 7);
  for (const SweepValue& v : sweep.values) {
    EXPECT_LT(v.result.metrics[0].mse_after_window[0], 1e-4) << v.value;
  }
  EXPECT_NE(sweep_error(prepared, "horizon", {4.5}).find("'horizon' must be an integer, got 4.5"),
            std::string::npos)
      << sweep_error(prepared, "horizon", {4.5});
}

// "substeps", where no observer of the scenario takes it, is the model spec's: each value is
// simulated again and run on that discretisation (the runs differ); 0 is refused naming it.
TEST(Sweep, SubstepsSweepTheModelsDiscretisation) {
  register_counted_decay();
  nlohmann::json spec = decay_scenario();
  spec["model"]["scheme"] = "euler";
  spec["model"]["parameters"]["a"] = 20.0;
  const PreparedScenario prepared = prepare_scenario(parse_scenario(spec, "decay-test"));
  const SweepRun sweep = run_sweep(prepared, "substeps", {1.0, 7.0});
  EXPECT_TRUE(sweep.model_parameter);
  ASSERT_EQ(sweep.values.size(), 2u);
  EXPECT_NE(sweep.values[0].result.metrics[1].mse[0], sweep.values[1].result.metrics[1].mse[0]);
  EXPECT_NE(sweep_error(prepared, "substeps", {0.0})
                .find("'substeps' = 0 is out of range: must be in 1..1000"),
            std::string::npos)
      << sweep_error(prepared, "substeps", {0.0});
}

TEST(Sweep, HostileSweepsAreRefusedNamingKeyAndValue) {
  register_counted_decay();
  const PreparedScenario prepared =
      prepare_scenario(parse_scenario(decay_scenario(), "decay-test"));
  const auto error_of = [&](const std::string& key, const std::vector<double>& values) {
    try {
      run_sweep(prepared, key, values);
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("<no error>");
  };
  EXPECT_EQ(error_of("a", {}), "sweep a: no values");
  EXPECT_EQ(error_of("a", {std::numeric_limits<double>::quiet_NaN()}),
            "sweep a: the value nan is not finite");
  const std::string unknown = error_of("no_such", {1.0});
  EXPECT_EQ(unknown.rfind("sweep no_such = 1: ", 0), 0u) << unknown;
  EXPECT_NE(unknown.find("or a parameter of its model"), std::string::npos) << unknown;
  // A rate the model refuses, or a huge one whose simulation leaves the doubles: named.
  EXPECT_EQ(error_of("a", {1e300}).rfind("sweep a = 1e+300: ", 0), 0u) << error_of("a", {1e300});

  PreparedScenario recorded = prepared;
  recorded.data.x.resize(0, 0);  // no truth
  try {
    run_sweep(recorded, "a", {1.0});
    FAIL() << "swept";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "sweep needs simulated data (the truth)");
  }
}

// A scenario file of a model nlobs does not ship, at `dir`/decay.json.
std::filesystem::path write_decay_file(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  const std::filesystem::path file = dir / "decay.json";
  std::ofstream(file) << decay_scenario().dump();
  return file;
}

// temp/nlobs_test_scenario_run_PID/NAME (created by write_decay_file).
std::filesystem::path scratch_dir(const std::string& name) {
  return test::scratch_path("nlobs_test_scenario_run", name);
}

// Equal sizes and entries (Eigen's == asserts equal sizes).
bool same(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() && a == b;
}

// The data file `nlobs run --data` reads: t, y1 of the first `steps` samples.
std::string csv_of(const Measurements& data, long steps) {
  std::ostringstream os;
  os << std::setprecision(17) << "t,y1\n";
  for (long k = 0; k < steps; ++k) os << data.t[k] << ',' << data.y(0, k) << '\n';
  return os.str();
}

TEST(ScenarioRequest, IsTheScenarioWithItsOverridesBuiltOnce) {
  register_counted_decay();
  const std::filesystem::path file = write_decay_file(scratch_dir("overrides"));
  const int before = decay_builds;
  const ScenarioRun asked =
      run_request({.scenario = file.string(), .steps = 120, .noise = 0.004, .seed = 9});
  EXPECT_EQ(decay_builds - before, 1) << "parse, prepare and run build the model once";

  // The same by hand: the file parsed, its fields edited, run.
  Scenario s = load_scenario(file.string());
  s.steps = 120, s.noise = 0.004, s.seed = 9;
  const ScenarioRun by_hand = run_scenario(s);
  ASSERT_EQ(asked.prepared.data.steps(), 120);
  EXPECT_TRUE(same(asked.prepared.data.y, by_hand.prepared.data.y));  // the same noise draw
  ASSERT_EQ(asked.result.estimates.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_TRUE(same(asked.result.estimates[i], by_hand.result.estimates[i])) << i;
  }
  // Another seed is another draw: the override reached the simulation.
  const ScenarioRun other =
      run_request({.scenario = file.string(), .steps = 120, .noise = 0.004, .seed = 10});
  EXPECT_FALSE(same(other.prepared.data.y, asked.prepared.data.y));
}

TEST(ScenarioRequest, ReadsItsDataFileForTheScenariosOwnModelFromALinkOrAFifo) {
  register_counted_decay();
  const std::filesystem::path dir = scratch_dir("data");
  const std::filesystem::path file = write_decay_file(dir);
  const PreparedScenario simulated = prepare_request({.scenario = file.string()});
  const std::string csv = csv_of(simulated.data, 200);
  const std::filesystem::path data = dir / "y.csv";
  std::ofstream(data) << csv;

  const int before = decay_builds;
  const ScenarioRun from_file =
      run_request({.scenario = file.string(), .data_file = data.string()});
  EXPECT_EQ(decay_builds - before, 1) << "the data's shape comes from the scenario's own model";
  EXPECT_EQ(from_file.prepared.source, data.string());
  EXPECT_FALSE(from_file.prepared.data.has_truth());
  ASSERT_EQ(from_file.prepared.data.steps(), 200);
  // What the file holds, read back to the last digit, gives the run given those measurements.
  Measurements given = simulated.data;
  given.t.conservativeResize(200);
  given.y.conservativeResize(Eigen::NoChange, 200);
  given.u.conservativeResize(Eigen::NoChange, 200);
  given.x.resize(0, 0);
  EXPECT_TRUE(same(from_file.prepared.data.y, given.y));
  const ScenarioRun from_memory =
      run_scenario(load_scenario(file.string()), {.data = given, .data_source = "memory"});
  EXPECT_TRUE(same(from_file.result.estimates[0], from_memory.result.estimates[0]));

  // A symbolic link to the file reads the file.
  const std::filesystem::path link = dir / "link.csv";
  std::filesystem::remove(link);
  std::filesystem::create_symlink(data, link);
  EXPECT_TRUE(
      same(run_request({.scenario = file.string(), .data_file = link.string()}).result.estimates[0],
           from_file.result.estimates[0]));

  // A FIFO (a shell's <(generate), a sensor's pipe) is read as it is written.
  const std::filesystem::path fifo = dir / "pipe.csv";
  std::filesystem::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::thread writer([&] { std::ofstream(fifo) << csv; });
  std::optional<ScenarioRun> from_fifo;
  try {
    from_fifo = run_request({.scenario = file.string(), .data_file = fifo.string()});
  } catch (const std::exception& e) {
    ADD_FAILURE() << e.what();
    const int release = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);  // the writer's open returns
    writer.join();
    ::close(release);
    return;
  }
  writer.join();
  ASSERT_TRUE(from_fifo);
  EXPECT_TRUE(same(from_fifo->result.estimates[0], from_file.result.estimates[0]));
}

TEST(ScenarioRequest, BadOverridesAndFilesAreNamedAndNothingRuns) {
  register_counted_decay();
  const std::filesystem::path dir = scratch_dir("bad");
  const std::filesystem::path file = write_decay_file(dir);
  // Nothing of a refused request runs: it is refused before the scenario counts as parsed (the
  // CLI's --out lock), or before any data or observer step.
  int parsed = 0, steps = 0;
  const auto error_of = [&](const ScenarioRequest& request, RunSettings settings = {}) {
    settings.progress = [&steps](long, long) { ++steps; };
    if (!settings.parsed) settings.parsed = [&parsed](const Scenario&) { ++parsed; };
    try {
      run_request(request, std::move(settings));
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("<no error>");
  };
  const std::string f = file.string();
  EXPECT_EQ(error_of({.scenario = f, .steps = 0}),
            "'steps' = 0 is out of range: must be in 1..10000000");
  EXPECT_EQ(error_of({.scenario = f, .steps = 100'000'000'000L}),
            "'steps' = 100000000000 is out of range: must be in 1..10000000");
  EXPECT_EQ(error_of({.scenario = f, .noise = std::numeric_limits<double>::quiet_NaN()}),
            "'noise' = nan is not a finite number >= 0");
  EXPECT_EQ(error_of({.scenario = f, .noise = -1.0}), "'noise' = -1 is not a finite number >= 0");
  EXPECT_EQ(error_of({.scenario = f, .noise = std::numeric_limits<double>::infinity()}),
            "'noise' = inf is not a finite number >= 0");
  EXPECT_EQ(error_of({.scenario = f, .allow_late = true}),
            "'allow_late' applies to a data file ('data_file'): a simulation's times always "
            "increase");
  std::ofstream(dir / "y.csv") << "t,y1\n0,1\n0.01,0.99\n";
  Measurements given;
  given.t = Eigen::VectorXd::LinSpaced(3, 0.0, 0.02);
  given.y = Eigen::MatrixXd::Ones(1, 3);
  given.u = Eigen::MatrixXd::Zero(0, 3);
  const std::string both = error_of({.scenario = f, .data_file = (dir / "y.csv").string()},
                                    {.data = given, .data_source = "memory"});
  EXPECT_NE(both.find("measurements were given as well"), std::string::npos) << both;
  EXPECT_EQ(parsed, 0) << "a refused request counted as parsed (the CLI's --out lock taken)";
  // A data file that cannot be read is found once the scenario is valid.
  EXPECT_EQ(error_of({.scenario = f, .data_file = (dir / "absent.csv").string()}),
            "data file '" + (dir / "absent.csv").string() + "' does not exist");
  EXPECT_EQ(error_of({.scenario = f, .data_file = dir.string()}),
            "data file '" + dir.string() + "' is a directory, not a file");
  // A data file of another model's shape: the file and line named.
  std::ofstream(dir / "wide.csv") << "0,1,2\n";
  const std::string wide = error_of({.scenario = f, .data_file = (dir / "wide.csv").string()});
  EXPECT_NE(wide.find("wide.csv:1"), std::string::npos) << wide;
  EXPECT_NE(error_of({.scenario = "no-such-scenario"}).find("no-such-scenario"), std::string::npos);
  EXPECT_EQ(steps, 0) << "an observer ran";
  // `parsed` comes before the data file is opened: a program's refusal there (its output
  // directory is taken) stops the request before a missing file is even noticed.
  const std::string taken = error_of(
      {.scenario = f, .data_file = (dir / "absent.csv").string()},
      {.parsed = [](const Scenario& s) { throw std::invalid_argument(s.name + ": taken"); }});
  EXPECT_EQ(taken, "decay-test: taken");
}

TEST(ScenarioRequest, ASimulationThatStopsEarlyIsReportedBeforeTheRunFails) {
  // The lander's mass x3 starts below zero: the model leaves its domain at the first sample.
  nlohmann::json j = to_json(load_scenario("pi-lander"));
  j["x0"][2] = -1.0;
  const std::filesystem::path dir = scratch_dir("early_end");
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "lander.json") << j.dump();
  std::string seen;
  try {
    run_request({.scenario = (dir / "lander.json").string()},
                {.prepared = [&seen](const PreparedScenario& p) { seen = p.data.stop_message; }});
    FAIL() << "ran";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("the simulation produced no samples"), std::string::npos)
        << e.what();
  }
  EXPECT_NE(seen.find("stopped at sample 0"), std::string::npos) << seen;
}

}  // namespace
}  // namespace nlobs
