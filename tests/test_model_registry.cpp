// The model registry with models nlobs does not ship: a user's Rössler system registered the
// way the built-ins are runs in a scenario file with every observer type whose condition it
// meets; the others are refused naming the condition. Duplicate names name both sources.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>

#include "nlobs/observers/baselines/baselines.hpp"
#include "nlobs/registry/observer_types.hpp"
#include "nlobs/registry/register_model.hpp"
#include "nlobs/runs/scenario.hpp"
#include "run_command.hpp"
#include "run_support.hpp"

namespace nlobs::cli {
namespace {

// Rössler (not in nlobs): x1' = -x2 - x3, x2' = x1 + a x2, x3' = b + x3 (x1 - c), y = x1.
struct Rossler : ModelSizes<3, 0, 1> {
  double a = 0.2, b = 0.2, c = 5.7;
  template <typename T>
  State<T> vector_field(const State<T>& x, const Input&, double) const {
    State<T> dx;
    dx << -x[1] - x[2], x[0] + a * x[1], b + x[2] * (x[0] - c);
    return dx;
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return x.template head<1>();
  }
};

// Two outputs and an input: no high-gain observer, no MVT (y is not [I 0] x).
struct TwoOutputs : ModelSizes<2, 1, 2> {
  double k = 1.0;
  template <typename T>
  State<T> vector_field(const State<T>& x, const Input& u, double) const {
    State<T> dx;
    dx << x[1], -k * x[0] + u[0];
    return dx;
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    Output<T> y;
    y << x[0] + x[1], x[0] - x[1];
    return y;
  }
};

// A spring x1' = x2, x2' = -w^2 x1, y = x1, with its hand embedding q = (x1, x2, -w^2 x1,
// -w^2 x2), alpha = L_f^4 h = -w^2 z3 and q's inverse: a form that holds the model's parameter
// (a default-constructed one is NaN, so an observer built from it is visibly wrong).
struct SpringEmbedding {
  static constexpr int kStates = 2, kDimension = 4;
  double w2 = std::nan("");
  template <typename T>
  Eigen::Matrix<T, 4, 1> operator()(const Eigen::Matrix<T, 2, 1>& x) const {
    Eigen::Matrix<T, 4, 1> z;
    z << x[0], x[1], -w2 * x[0], -w2 * x[1];
    return z;
  }
  template <typename T>
  T alpha(const Eigen::Matrix<T, 4, 1>& z) const {
    return -w2 * z[2];
  }
  Eigen::Vector2d inverse(const Eigen::Vector4d& z) const { return z.head<2>(); }
};

struct Spring : ModelSizes<2, 0, 1> {
  double w = 2.0;
  template <typename T>
  State<T> vector_field(const State<T>& x, const Input&, double) const {
    State<T> dx;
    dx << x[1], -w * w * x[0];
    return dx;
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return x.template head<1>();
  }
};

std::optional<SpringEmbedding> hand_embedding(const Spring& m) {
  return SpringEmbedding{m.w * m.w};
}

void register_once() {
  static const bool done = [] {
    model_registry().add(
        model_entry(ModelDefinition<Rossler>{
            .name = "rossler",
            .description = "Rössler attractor, y = x1 (a test's model)",
            .parameters =
                {{"a", "x2' = x1 + a x2", [](Rossler& m) -> double& { return m.a; }},
                 {"b", "x3' = b + x3 (x1 - c)", [](Rossler& m) -> double& { return m.b; }},
                 {"c", "x3' = b + x3 (x1 - c)", [](Rossler& m) -> double& { return m.c; }}},
            .build =
                [](const Rossler& m) {
                  if (!(m.c > 0.0)) throw std::invalid_argument("'c' must be > 0");
                  return m;
                }}),
        "test_model_registry");
    // A user's observer type: a Luenberger observer whose gain is one number per state.
    observer_type_registry().add(
        observer_type_entry(ObserverTypeDefinition<Eigen::VectorXd>{
            .name = "scalar_luenberger",
            .description = "a test's observer type",
            .condition = "one output",
            .keys = {{"gains", "one per state", ""}, {"initial", "start", "initial_guess"}},
            .parse =
                [](JsonReader& o, const ModelInstance& model) {
                  Eigen::VectorXd g = o.required_vector("gains");
                  if (g.size() != model.discrete.states()) o.fail("'gains' must have n entries");
                  return g;
                },
            .write =
                [](const Eigen::VectorXd& g, nlohmann::json& out) {
                  out["gains"] = std::vector<double>(g.begin(), g.end());
                },
            .build = [](const Eigen::VectorXd& g,
                        const ObserverBuild& b) -> std::unique_ptr<Observer> {
              if (b.model.discrete.outputs() != 1) throw InvalidInput("needs one output");
              LuenbergerOptions o;
              o.name = "scalar_luenberger";
              o.initial_estimate = b.start;
              o.gain = g;
              return std::make_unique<LuenbergerObserver<AnyModel>>(b.design, o);
            }}),
        "test_model_registry");
    model_registry().add(
        model_entry(ModelDefinition<Spring>{
            .name = "spring",
            .description = "a test's spring with a hand embedding",
            .parameters = {{"w", "x2' = -w^2 x1", [](Spring& m) -> double& { return m.w; }}}}),
        "test_model_registry");
    model_registry().add(model_entry(ModelDefinition<TwoOutputs>{
                             .name = "two-outputs", .description = "a test's two-output model"}),
                         "test_model_registry");
    return true;
  }();
  (void)done;
}

nlohmann::json rossler_scenario(const nlohmann::json& observers) {
  return {{"name", "rossler-test"},
          {"model", {{"name", "rossler"}, {"parameters", {{"c", 5.7}}}, {"step", 0.01}}},
          {"x0", {1.0, 1.0, 0.5}},
          {"initial_guess", {1.5, 0.5, 0.2}},
          {"steps", 1500},
          {"settle_time", 10.0},
          {"observers", observers}};
}

RunResult run(const nlohmann::json& json) {
  const Scenario s = parse_scenario(json, "test scenario");
  const ModelInstance model = scenario_model(s);
  const Measurements data = simulate_scenario(s, model.discrete);
  auto observers = make_observers(s, model, false);
  return run_observers(data, observers, 1000);
}

std::string error_of(const nlohmann::json& json) {
  try {
    run(json);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "<no error>";
}

// sliding_mode's gamma has the default docs/observers.md gives (SlidingModeOptions::gamma, 1):
// an entry without it runs, and `nlobs list observers` says so.
TEST(ModelRegistry, SlidingModeTakesItsDocumentedDefaultGamma) {
  register_once();
  const RunResult r = run(rossler_scenario(nlohmann::json::parse(
      R"([{"type": "sliding_mode", "Q": [0.05, 0.05, 0.0], "R": [1.0, 0.5, 0.0]}])")));
  ASSERT_EQ(r.metrics.size(), 1u);
  EXPECT_TRUE(r.metrics[0].mse_after_window.allFinite());
  const ObserverTypeEntry& entry = observer_type_registry().get("sliding_mode");
  bool listed = false;
  for (const KeyInfo& k : entry.keys) {
    if (k.key == "gamma") listed = k.default_value == "1";
  }
  EXPECT_TRUE(listed);
}

TEST(ModelRegistry, UserModelRunsWithEveryObserverTypeItsConditionsAllow) {
  register_once();
  const nlohmann::json observers = nlohmann::json::parse(R"([
    {"type": "window", "engine": "newton", "tol": 1e-10},
    {"type": "window", "engine": "ceres", "window": 8},
    {"type": "ekf", "process_covariance": [[1e-8, 0, 0], [0, 1e-8, 0], [0, 0, 1e-8]],
     "measurement_covariance": [[1e-6]], "initial_covariance": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]},
    {"type": "luenberger", "gain": [0.3, 0.1, 0.0]},
    {"type": "sliding_mode", "Q": [0.05, 0.05, 0.0], "R": [1.0, 0.5, 0.0], "gamma": 1},
    {"type": "mvt", "error_guess": [-0.5, 0.5, 0.3]},
    {"type": "high_gain", "N": 3, "theta": 0.2},
    {"type": "finite_difference"}
  ])");
  const RunResult r = run(rossler_scenario(observers));
  ASSERT_EQ(r.metrics.size(), 8u);
  for (const ObserverMetrics& m : r.metrics) {
    SCOPED_TRACE(m.name);
    ASSERT_EQ(m.mse_after_window.size(), 3);
    EXPECT_TRUE(m.mse_after_window.allFinite());
  }
  // Noise-free data: the estimators that reconstruct the state do it (finite differences give
  // (y, y', y''), other coordinates; Luenberger and sliding mode are not tuned for Rössler).
  for (size_t i : {0u, 1u, 2u, 5u, 6u}) {
    SCOPED_TRACE(r.metrics[i].name);
    EXPECT_LT(r.metrics[i].mse_after_window.maxCoeff(), 1e-3);
  }
}

TEST(ModelRegistry, AUserHandEmbeddingIsUsedWithTheModelsOwnParameters) {
  register_once();
  const nlohmann::json observers = nlohmann::json::parse(R"([
    {"type": "high_gain", "name": "explicit", "N": 4, "theta": 0.3, "map": "explicit",
     "alpha": "explicit"},
    {"type": "high_gain", "name": "inverse", "N": 4, "theta": 0.3, "map": "explicit",
     "alpha": "explicit", "inverse": true},
    {"type": "high_gain", "name": "taylor", "N": 4, "theta": 0.3}
  ])");
  const nlohmann::json scenario = {
      {"name", "spring-test"}, {"model", {{"name", "spring"}, {"parameters", {{"w", 3.0}}}}},
      {"x0", {1.0, 0.0}},      {"initial_guess", {0.5, 0.5}},
      {"steps", 1500},         {"observers", observers}};
  const RunResult r = run(scenario);
  ASSERT_EQ(r.metrics.size(), 3u);
  for (const ObserverMetrics& m : r.metrics) {
    SCOPED_TRACE(m.name);
    ASSERT_TRUE(m.mse_after_window.allFinite()) << m.mse_after_window.transpose();
    EXPECT_LT(m.mse_after_window.maxCoeff(), 1e-4);
  }
}

TEST(ModelRegistry, ObserverTypesRefuseAModelThatMissesTheirConditionNamingIt) {
  register_once();
  EXPECT_NE(error_of(rossler_scenario(nlohmann::json::parse(R"([{"type": "modulating"}])")))
                .find("modulating on model 'rossler': no canonical form"),
            std::string::npos);
  nlohmann::json two =
      rossler_scenario(nlohmann::json::parse(R"([{"type": "high_gain", "N": 3}])"));
  two["model"] = {{"name", "two-outputs"}};
  two["x0"] = {1.0, 0.0};
  two["initial_guess"] = {0.0, 0.0};
  const std::string hg = error_of(two);
  EXPECT_NE(hg.find("high_gain on model 'two-outputs'"), std::string::npos) << hg;
  EXPECT_NE(hg.find("one output"), std::string::npos) << hg;
  two["observers"] = nlohmann::json::parse(R"([{"type": "mvt", "error_guess": [0, 0]}])");
  const std::string mvt = error_of(two);
  EXPECT_NE(mvt.find("y = C x with C = [I_m 0]"), std::string::npos) << mvt;
  // The window estimator takes any model.
  two["observers"] = nlohmann::json::parse(R"([{"type": "window", "engine": "newton"}])");
  EXPECT_EQ(error_of(two), "<no error>");
}

TEST(ModelRegistry, ParametersAreReadStrictlyAndCheckedByTheModel) {
  register_once();
  nlohmann::json s = rossler_scenario(nlohmann::json::parse(R"([{"type": "window"}])"));
  s["model"]["parameters"] = {{"d", 1.0}};
  EXPECT_NE(error_of(s).find("model.parameters"), std::string::npos) << error_of(s);
  EXPECT_NE(error_of(s).find("'d'"), std::string::npos) << error_of(s);
  s["model"]["parameters"] = {{"c", -1.0}};
  EXPECT_NE(error_of(s).find("'c' must be > 0"), std::string::npos) << error_of(s);
  s["model"]["parameters"] = {{"c", "five"}};
  EXPECT_NE(error_of(s).find("test scenario.model.parameters: 'c'"), std::string::npos)
      << error_of(s);
  s["model"] = {{"name", "rossler"}, {"step", -0.01}};
  EXPECT_NE(error_of(s).find("test scenario.model: 'step'"), std::string::npos) << error_of(s);
  s["model"] = {{"name", "rosler"}};
  const std::string unknown = error_of(s);
  EXPECT_NE(unknown.find("unknown model 'rosler'"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("rossler"), std::string::npos) << unknown;  // the valid list has it
  EXPECT_NE(unknown.find("modified-chua"), std::string::npos) << unknown;
}

TEST(ModelRegistry, ADuplicateNameNamesBothSourcesAndKeepsTheFirst) {
  register_once();
  try {
    model_registry().add(
        model_entry(ModelDefinition<Rossler>{.name = "lorenz", .description = "impostor"}),
        "libimpostor.so");
    FAIL() << "a duplicate name was accepted";
  } catch (const InvalidInput& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'lorenz' from libimpostor.so"), std::string::npos) << what;
    EXPECT_NE(what.find("already registered by built-in"), std::string::npos) << what;
  }
  EXPECT_EQ(model_registry().get("lorenz").states, 3);
  EXPECT_EQ(model_registry().source("lorenz"), "built-in");
  EXPECT_EQ(model_registry().source("rossler"), "test_model_registry");
  EXPECT_THROW(model_registry().add(model_entry(ModelDefinition<Rossler>{.name = "bad name"})),
               InvalidInput);
}

TEST(ModelRegistry, EntriesDescribeTheirKeysSizesAndObserverFamilies) {
  register_once();
  const ModelEntry& r = model_registry().get("rossler");
  EXPECT_EQ(r.states, 3);
  EXPECT_EQ(r.outputs, 1);
  ASSERT_EQ(r.parameters.size(), 3u);
  EXPECT_EQ(r.parameters[2].key, "c");
  EXPECT_EQ(r.parameters[2].default_value, "5.7");
  const auto has = [](const ModelEntry& e, const std::string& f) {
    return std::find(e.families.begin(), e.families.end(), f) != e.families.end();
  };
  EXPECT_TRUE(has(r, "high_gain"));
  EXPECT_TRUE(has(r, "mvt"));
  EXPECT_TRUE(has(r, "ukf"));  // every model: listed since the UKF and MHE took any (they did)
  EXPECT_TRUE(has(r, "mhe"));
  // A model of run-time size: the families of AnyModel, none that need fixed sizes.
  const ModelEntry& chain = model_registry().get("reaction-diffusion");
  EXPECT_TRUE(has(chain, "ekf") && has(chain, "ukf") && has(chain, "mhe"));
  EXPECT_FALSE(has(chain, "mvt") || has(chain, "high_gain") || has(chain, "modulating"));
  EXPECT_FALSE(has(r, "modulating"));
  EXPECT_FALSE(has(model_registry().get("two-outputs"), "high_gain"));
  EXPECT_TRUE(has(model_registry().get("pendulum"), "modulating"));
}

TEST(ObserverTypeRegistry, AUserTypeIsReadWrittenAndBuiltLikeABuiltIn) {
  register_once();
  const nlohmann::json observers = nlohmann::json::parse(
      R"([{"type": "scalar_luenberger", "gains": [0.3, 0.1, 0.0]},
          {"type": "luenberger", "gain": [0.3, 0.1, 0.0]}])");
  const RunResult r = run(rossler_scenario(observers));
  ASSERT_EQ(r.metrics.size(), 2u);
  // The same gain through the user's type and the built-in one: the same estimates.
  EXPECT_EQ(r.estimates[0], r.estimates[1]);
  // Written back and read again (a run's scenario.json).
  const Scenario s = parse_scenario(rossler_scenario(observers), "test");
  const Scenario back = parse_scenario(to_json(s), "round trip");
  EXPECT_EQ(observer_spec_json(back.observers[0]), observer_spec_json(s.observers[0]));
  // Strict keys, the type's own checks, and the valid list naming the user's type.
  nlohmann::json bad = rossler_scenario(
      nlohmann::json::parse(R"([{"type": "scalar_luenberger", "gains": [1, 2, 3], "gain": 1}])"));
  EXPECT_NE(error_of(bad).find("'gain'"), std::string::npos) << error_of(bad);
  bad["observers"][0].erase("gain");
  bad["observers"][0]["gains"] = {1, 2};
  EXPECT_NE(error_of(bad).find("'gains' must have n entries"), std::string::npos) << error_of(bad);
  bad["observers"][0]["type"] = "scalar-luenberger";
  const std::string unknown = error_of(bad);
  EXPECT_NE(unknown.find("unknown observer type 'scalar-luenberger'"), std::string::npos)
      << unknown;
  EXPECT_NE(unknown.find("scalar_luenberger"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("finite_difference"), std::string::npos) << unknown;
  // A taken name: both sources named, the built-in kept.
  try {
    auto entry = observer_type_registry().get("ekf");
    observer_type_registry().add(entry, "libother.so");
    FAIL() << "a duplicate observer type was accepted";
  } catch (const InvalidInput& e) {
    EXPECT_NE(
        std::string(e.what()).find("'ekf' from libother.so is already registered by built-in"),
        std::string::npos)
        << e.what();
  }
  EXPECT_THROW(observer_type_entry(ObserverTypeDefinition<int>{.name = "no_build"}), InvalidInput);
}

}  // namespace
}  // namespace nlobs::cli
