// Exceptions from user code in the run harness, the registries and the CLI (docs/extending.md,
// "Exceptions from user code"): a user's model that throws in an observer's step is a failed step
// named with the observer, the model, the sample and its time (the run goes on, the last good
// estimate kept); the true system's model that throws ends the simulation with an error naming
// the same; a user's factory, hook or problem builder that throws anything is refused by the
// name of the user's object. `throw 42` included everywhere: nothing ends in std::terminate.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "cli_test_files.hpp"
#include "nlobs/registry/observer_types.hpp"
#include "nlobs/registry/problem_sets.hpp"
#include "nlobs/registry/register_model.hpp"
#include "nlobs/runs/scenario.hpp"
#include "nlobs/solvers/engine_registry.hpp"
#include "run_command.hpp"
#include "run_support.hpp"
#include "solve_chua_window.hpp"

namespace nlobs::cli {
namespace {

// A spring x1' = x2, x2' = -x1, y = x1 whose vector field throws for t > throw_after: `throw 42`
// when nonstandard = 1, else a std::runtime_error whose text holds an escape sequence and a line
// break. With jet_only = 1 it throws only in the AD scalar (the observers' Jacobians), so the
// true system (simulated in doubles) runs.
struct Throwing : ModelSizes<2, 0, 1> {
  double throw_after = 1e300, nonstandard = 0.0, jet_only = 0.0;
  template <typename T>
  State<T> vector_field(const State<T>& x, const Input&, double t) const {
    if (t > throw_after && !(jet_only != 0.0 && std::is_same_v<T, double>)) {
      if (nonstandard != 0.0) throw 42;
      throw std::runtime_error("the model gave up\x1b[31m\nforged line");
    }
    State<T> dx;
    dx << x[1], -x[0];
    return dx;
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return x.template head<1>();
  }
};

void register_once() {
  static const bool done = [] {
    const auto field = [](double Throwing::*member) {
      return [member](Throwing& m) -> double& { return m.*member; };
    };
    model_registry().add(model_entry(ModelDefinition<Throwing>{
                             .name = "throwing-model",
                             .description = "a test's spring whose vector field throws",
                             .parameters = {{"throw_after", "", field(&Throwing::throw_after)},
                                            {"nonstandard", "", field(&Throwing::nonstandard)},
                                            {"jet_only", "", field(&Throwing::jet_only)}},
                             .build =
                                 [](const Throwing& m) {
                                   if (m.throw_after == -1.0)
                                     throw 42;  // a build that throws a non-standard value
                                   return m;
                                 }}),
                         "test_user_exceptions_run");
    // An observer type whose hooks throw 42 when its spec says so.
    observer_type_registry().add(
        observer_type_entry(ObserverTypeDefinition<std::string>{
            .name = "throwing_observer",
            .description = "a test's observer type whose hooks throw",
            .keys = {{"throws_in", "parse | write | build | report", ""}},
            .parse =
                [](JsonReader& o, const ModelInstance&) {
                  const std::string where = o.text("throws_in").value_or("");
                  if (where == "parse") throw 42;
                  return where;
                },
            .write =
                [](const std::string& where, nlohmann::json& out) {
                  if (where == "write") throw 42;
                  out["throws_in"] = where;
                },
            .build = [](const std::string& where,
                        const ObserverBuild&) -> std::unique_ptr<Observer> {
              if (where == "build") throw std::runtime_error("no\x1b]0;title\x07 observer");
              throw 42;
            },
            .report = [](const std::string& where, std::vector<std::string>*) -> nlohmann::json {
              if (where == "report") throw 42;
              return nlohmann::json::array();
            }}),
        "test_user_exceptions_run");
    // An engine whose factory throws 42, and one whose solve throws 42.
    EngineRegistry<Dynamic>::global().add(
        {.name = "throwing-factory",
         .description = "a test's engine whose factory throws",
         .make = [](EngineSpecReader&, SolverOptions) -> std::unique_ptr<Engine<Dynamic>> {
           throw 42;
         }},
        "test_user_exceptions_run");
    struct ThrowingEngine : Engine<Dynamic> {
      explicit ThrowingEngine(SolverOptions o) : Engine<Dynamic>(std::move(o)) {}
      std::string_view name() const override { return "throwing-solve"; }
      Summary solve(const FixedPointProblem<Dynamic>&, Vector<Dynamic>&) override { throw 42; }
    };
    EngineRegistry<Dynamic>::global().add(
        {.name = "throwing-solve",
         .description = "a test's engine whose solve throws",
         .make = [](EngineSpecReader&, SolverOptions o) -> std::unique_ptr<Engine<Dynamic>> {
           return std::make_unique<ThrowingEngine>(o);
         }},
        "test_user_exceptions_run");
    problem_set_registry().add(
        ProblemSetEntry{.name = "throwing-set",
                        .description = "a test's set whose problems cannot be built",
                        .problems = []() -> std::vector<TestProblem> { throw 42; }},
        "test_user_exceptions_run");
    return true;
  }();
  (void)done;
}

nlohmann::json scenario(const nlohmann::json& parameters, const nlohmann::json& observers) {
  return {{"name", "throwing-test"},
          {"model", {{"name", "throwing-model"}, {"parameters", parameters}, {"step", 0.01}}},
          {"x0", {1.0, 0.0}},
          {"initial_guess", {0.5, 0.5}},
          {"steps", 100},
          {"observers", observers}};
}

const nlohmann::json kObservers = nlohmann::json::parse(R"([
  {"type": "ekf"},
  {"type": "window", "engine": "newton", "window": 2},
  {"type": "luenberger", "gain": [0.5, 0.1]}
])");

// run_scenario on the scenario written to a file: its error, or "" and the printed table.
std::string run_error(const nlohmann::json& json, std::string* table = nullptr) {
  const auto path = test::scratch_path("nlobs_test_user_exceptions", "scenario.json");
  test::write_file(path, json.dump());
  std::ostringstream out, err;
  try {
    run_scenario(path.string(), {}, out, err);
  } catch (const std::exception& e) {
    return e.what();
  }
  if (table) *table = out.str();
  return "";
}

TEST(UserExceptionsRun, AThrowingModelInAnObserversStepIsAFailedStepNamedWithItsSample) {
  register_once();
  for (const double nonstandard : {0.0, 1.0}) {
    SCOPED_TRACE(nonstandard != 0.0 ? "throw 42" : "std::runtime_error");
    const nlohmann::json json = scenario(
        {{"throw_after", 0.3}, {"nonstandard", nonstandard}, {"jet_only", 1.0}}, kObservers);
    const Scenario s = parse_scenario(json, "test scenario");
    const ModelInstance model = scenario_model(s);
    const Measurements data = simulate_scenario(s, model.discrete);
    ASSERT_EQ(data.steps(), 100);  // the true system runs in doubles: it does not throw
    auto observers = make_observers(s, model, false);
    const RunResult r = run_observers(data, observers);
    ASSERT_EQ(r.metrics.size(), 3u);
    for (size_t i : {0u, 1u}) {  // the EKF and the window estimator differentiate the model
      const ObserverMetrics& m = r.metrics[i];
      SCOPED_TRACE(m.name);
      // "k = 31 (t = 0.31): observer 'ekf' on model 'throwing-model' threw: <text>"
      // Parsed by hand: <regex> trips GCC 12's -Wmaybe-uninitialized under ASan.
      long k = -1;
      double t_named = -1.0;
      int consumed = 0;
      ASSERT_EQ(
          std::sscanf(m.first_failure.c_str(), "k = %ld (t = %lf): %n", &k, &t_named, &consumed), 2)
          << m.first_failure;
      ASSERT_GT(consumed, 0) << m.first_failure;
      EXPECT_GE(k, 30);  // the first evaluation past t = 0.3
      EXPECT_LE(k, 32);
      EXPECT_DOUBLE_EQ(t_named, data.t[k]);
      const std::string who = "observer '" + m.name + "' on model 'throwing-model' threw: ";
      EXPECT_NE(m.first_failure.find(who), std::string::npos) << m.first_failure;
      const std::string text = nonstandard != 0.0 ? "a non-standard exception"
                                                  : "the model gave up\\x1b[31m\\x0aforged line";
      EXPECT_NE(m.first_failure.find(who + text), std::string::npos) << m.first_failure;
      // Every later step throws too: counted, and the last good estimate is kept.
      ASSERT_TRUE(m.failures.count("observer_threw")) << m.first_failure;
      EXPECT_EQ(m.failures.at("observer_threw"), 100 - k);
      EXPECT_TRUE(r.estimates[i].col(k - 1).allFinite());
      for (long j = k; j < 100; ++j) EXPECT_EQ(r.estimates[i].col(j), r.estimates[i].col(k - 1));
    }
    // An observer that never differentiates the model runs on, untouched.
    EXPECT_TRUE(r.metrics[2].failures.empty()) << r.metrics[2].first_failure;
    EXPECT_TRUE(r.metrics[2].first_failure.empty());
  }
  // `nlobs run` prints the same: no terminate, no unnamed message.
  std::string table;
  EXPECT_EQ(run_error(scenario({{"throw_after", 0.3}, {"nonstandard", 1.0}, {"jet_only", 1.0}},
                               kObservers),
                      &table),
            "");
  EXPECT_NE(table.find("first failure of ekf: k = "), std::string::npos) << table;
  EXPECT_NE(table.find("observer 'ekf' on model 'throwing-model' threw: a non-standard exception"),
            std::string::npos)
      << table;
  EXPECT_NE(table.find("observer_threw"), std::string::npos) << table;
}

TEST(UserExceptionsRun, AThrowingTrueSystemEndsTheRunNamingModelSampleAndTime) {
  register_once();
  // RK4 from sample 50 (t = 0.5) evaluates the field at t = 0.505 first.
  EXPECT_EQ(run_error(scenario({{"throw_after", 0.5}}, kObservers)),
            "simulate: model 'throwing-model' of the true system threw at sample 50 (t = 0.5): "
            "the model gave up\\x1b[31m\\x0aforged line");
  EXPECT_EQ(run_error(scenario({{"throw_after", 0.5}, {"nonstandard", 1.0}}, kObservers)),
            "simulate: model 'throwing-model' of the true system threw at sample 50 (t = 0.5): "
            "a non-standard exception");
}

TEST(UserExceptionsRun, ThrowingHooksFactoriesAndBuildersAreRefusedByName) {
  register_once();
  const auto observer = [](const std::string& where) {
    return scenario(nlohmann::json::object(),
                    {{{"type", "throwing_observer"}, {"throws_in", where}}});
  };
  // The observer's place in the scenario, then its type.
  const auto expect_named = [](const std::string& error, const std::string& expected) {
    EXPECT_NE(error.find(".observers[0]: " + expected), std::string::npos) << error;
  };
  expect_named(run_error(observer("parse")),
               "observer type 'throwing_observer': its parse threw: a non-standard exception");
  expect_named(run_error(observer("build")),
               "observer type 'throwing_observer': its build threw: no\\x1b]0;title\\x07 observer");
  try {
    observer_reports(parse_scenario(observer("report"), "test"), nullptr);
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(),
                 "throwing-test.observers[0]: observer type 'throwing_observer': its report "
                 "threw: a non-standard exception");
  }
  ObserverSpec spec{.type = "throwing_observer", .spec = std::string("write")};
  try {
    observer_spec_json(spec);
    ADD_FAILURE() << "no error";
  } catch (const InvalidInput& e) {
    EXPECT_STREQ(e.what(),
                 "observer type 'throwing_observer': its write threw: a non-standard exception");
  }
  // The model's build.
  const std::string build = run_error(scenario({{"throw_after", -1.0}}, kObservers));
  EXPECT_NE(build.find("model 'throwing-model': its build threw a non-standard exception"),
            std::string::npos)
      << build;
  // An engine's factory, by name (a scenario's engine, `nlobs solve`).
  try {
    EngineRegistry<Dynamic>::global().create("throwing-factory");
    ADD_FAILURE() << "no error";
  } catch (const InvalidInput& e) {
    EXPECT_STREQ(e.what(),
                 "engine 'throwing-factory' from test_user_exceptions_run: its factory threw: a "
                 "non-standard exception");
  }
  // A problem set's builder.
  try {
    build_problem_set(*problem_set_registry().find("throwing-set"));
    ADD_FAILURE() << "no error";
  } catch (const InvalidInput& e) {
    EXPECT_STREQ(e.what(),
                 "problem set 'throwing-set': building its problems threw: a non-standard "
                 "exception");
  }
}

TEST(UserExceptionsRun, AnEngineThatThrowsIsARowOfSolveChuaWindow) {
  register_once();
  const std::vector<SolveRow> rows = solve_chua_window({"throwing-solve", "newton"}, 1e-10, false);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].status, "engine_threw");
  EXPECT_EQ(rows[0].message, "throwing-solve threw: a non-standard exception");
  EXPECT_EQ(rows[1].status, "converged");
  std::ostringstream table;
  print_table(rows, 1e-10, table);
  EXPECT_NE(table.str().find("throwing-solve threw: a non-standard exception"), std::string::npos);
  EXPECT_EQ(to_json(rows)[0]["message"], "throwing-solve threw: a non-standard exception");
}

}  // namespace
}  // namespace nlobs::cli
