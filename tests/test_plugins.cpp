// Plugins: the example plugin (examples/plugin: a model, an engine and a problem set nlobs does
// not ship) loaded at run time works wherever a built-in does — scenarios with the observer
// types its model admits, the suite beside KINSOL and MINPACK, the CLI — and the loader refuses
// every library it must (no file, a directory, not a library, not a plugin, another nlobs, a
// throwing registration, a taken name) with a message naming the plugin, registering nothing.
// ctest runs every test in its own process: each starts with the built-ins only.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bad_broyden_engine.hpp"
#include "cli_test_files.hpp"
#include "nlobs/reference/problem_suite.hpp"
#include "nlobs/registry/plugin.hpp"
#include "run_command.hpp"
#include "run_support.hpp"
#include "scenario.hpp"

namespace nlobs {
namespace {

namespace fs = std::filesystem;

const std::string kExample = NLOBS_EXAMPLE_PLUGIN;

std::string test_plugin(const std::string& name) {
  return std::string(NLOBS_PLUGIN_DIR) + "/lib" + name + ".so";
}

// The message load_plugin refuses `path` with ("<loaded>" when it loads).
std::string refusal(const std::string& path) {
  try {
    load_plugin(path);
  } catch (const InvalidInput& e) {
    return e.what();
  }
  return "<loaded>";
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(Plugins, TheExamplePluginRegistersOneEntryOfEachKind) {
  const LoadedPlugin loaded = load_plugin(kExample);
  EXPECT_EQ(loaded.source, kExample);
  EXPECT_EQ(loaded.models, std::vector<std::string>{"fitzhugh-nagumo"});
  EXPECT_EQ(loaded.engines, std::vector<std::string>{"bad-broyden"});
  EXPECT_EQ(loaded.problem_sets, std::vector<std::string>{"example"});
  EXPECT_EQ(loaded.observer_types, std::vector<std::string>{"output_injection"});
  EXPECT_EQ(observer_type_registry().source("output_injection"), kExample);
  EXPECT_EQ(model_registry().source("fitzhugh-nagumo"), kExample);
  EXPECT_EQ(problem_set_registry().source("example"), kExample);
  EXPECT_EQ(EngineRegistry<Dynamic>::global().source("bad-broyden"), kExample);
  // One registration at Dynamic serves every fixed size.
  EXPECT_NE(EngineRegistry<2>::global().create("bad-broyden:backtracks=4"), nullptr);
  EXPECT_NE(EngineRegistry<7>::global().create("bad-broyden"), nullptr);
  // The built-ins are still there, and the plugin's entries are listed after them.
  EXPECT_EQ(model_registry().names().back(), "fitzhugh-nagumo");
  EXPECT_TRUE(model_registry().contains("lorenz"));
}

TEST(Plugins, APluginModelRunsWithTheObserverTypesItAdmitsAndAPluginEngine) {
  load_plugin(kExample);
  std::ifstream file(NLOBS_EXAMPLE_SCENARIO);
  ASSERT_TRUE(file) << NLOBS_EXAMPLE_SCENARIO;
  const nlohmann::json json = nlohmann::json::parse(file);
  const cli::Scenario s = cli::parse_scenario(json, NLOBS_EXAMPLE_SCENARIO);
  const ModelInstance model = cli::scenario_model(s);
  const Measurements data = cli::simulate_scenario(s, model.discrete);
  auto observers = cli::make_observers(s, model, false);
  const RunResult r = run_observers(data, observers, 200);  // after 10 s, the settle time
  ASSERT_EQ(r.metrics.size(), 6u);
  for (const ObserverMetrics& m : r.metrics) {
    SCOPED_TRACE(m.name);
    ASSERT_EQ(m.mse_after_window.size(), 2);
    EXPECT_TRUE(m.mse_after_window.allFinite());
    EXPECT_TRUE(m.failures.empty());
  }
  // Noise-free data: the windows (Newton's and the plugin's Broyden), the EKF, the MVT and
  // high-gain observers reconstruct the state.
  EXPECT_EQ(r.metrics[1].engine, "bad-broyden");
  for (size_t i = 0; i < 5; ++i) {
    SCOPED_TRACE(r.metrics[i].name);
    EXPECT_LT(r.metrics[i].mse_after_window.maxCoeff(), 1e-6);
  }
  // The plugin's observer type corrects x1 only; x2 follows the model, whose error decays at
  // rate eps b = 0.064 1/s: converging, slowly (measured 5.2e-3 for the scenario's g = 0.5).
  EXPECT_EQ(r.metrics[5].name, "output_injection");
  EXPECT_LT(r.metrics[5].mse_after_window.maxCoeff(), 2e-2);
  EXPECT_LT(r.metrics[5].mse_after_window.maxCoeff(), r.metrics[5].mse.maxCoeff());
  // The modulating observer needs a canonical form the model does not supply: named.
  nlohmann::json modulating = json;
  modulating["observers"] = nlohmann::json::parse(R"([{"type": "modulating"}])");
  try {
    const cli::Scenario m = cli::parse_scenario(modulating, "modulating");
    cli::make_observers(m, cli::scenario_model(m), false);
    ADD_FAILURE() << "the modulating observer accepted a model without a canonical form";
  } catch (const std::exception& e) {
    EXPECT_TRUE(contains(e.what(), "modulating on model 'fitzhugh-nagumo': no canonical form"))
        << e.what();
  }
}

TEST(Plugins, APluginEngineRunsInTheSuiteBesideKinsolAndMinpackOnAPluginSet) {
  load_plugin(kExample);
  const ProblemSelection selection = select_problems("example", problem_set_registry());
  ASSERT_EQ(selection.problems.size(), 2u);
  const auto rows = reference::run_suite(*selection.set, selection.problems,
                                         {"bad-broyden", "kinsol:newton", "minpack:hybrj"});
  ASSERT_EQ(rows.size(), 12u);  // 2 problems × 2 starts × 3 solvers
  int broyden_solved = 0;
  for (const auto& row : rows) {
    SCOPED_TRACE(row.problem + " " + row.start + " " + row.solver);
    if (row.solver == "bad-broyden") broyden_solved += row.solved;
    if (row.problem == "circle-line" && row.solved) {
      EXPECT_LT(row.error, 1e-8);  // the known root (1, 1), inside the box
    }
  }
  EXPECT_GE(broyden_solved, 3);
}

// The example's engine on its own: success, and each failure a status, never a wrong answer.
TEST(Plugins, TheExampleBroydenEngineSolvesAndFailsClearly) {
  using Engine = example::BadBroydenEngine<2>;
  SolverOptions options;
  options.stop.residual_tolerance = 1e-12;
  {  // Rosenbrock's F = (10 (x2 − x1²), 1 − x1) from the far start of MGH
    Engine engine(options, {});
    const auto problem = FixedPointProblem<2>::with_autodiff(
        [](const auto& x, auto& g) {
          g[0] = x[0] + 10.0 * (x[1] - x[0] * x[0]);
          g[1] = x[1] + 1.0 - x[0];
        },
        2);
    Vector<2> x(-1.2, 1.0);
    const Summary s = engine.solve(problem, x);
    EXPECT_EQ(s.status, Status::kConverged) << s.brief_report();
    EXPECT_NEAR(x[0], 1.0, 1e-9);
    EXPECT_NEAR(x[1], 1.0, 1e-9);
    EXPECT_TRUE(s.usable());
  }
  {  // F = (x1² − 1, x2) from x1 = 0: J_F = diag(0, 1) is singular there
    Engine engine(options, {});
    const auto problem = FixedPointProblem<2>::with_autodiff(
        [](const auto& x, auto& g) {
          g[0] = x[0] + x[0] * x[0] - 1.0;
          g[1] = x[1] + x[1];
        },
        2);
    Vector<2> x(0.0, 1.0);
    const Summary s = engine.solve(problem, x);
    EXPECT_EQ(s.status, Status::kSingularJacobian);
    EXPECT_FALSE(s.usable());
  }
  // F = x², a double root: Broyden converges linearly, slowly.
  const auto squares = FixedPointProblem<2>::with_autodiff(
      [](const auto& x, auto& g) { g = x + x.cwiseProduct(x); }, 2);
  {  // F = log x from x < 0: NaN at once
    Engine engine(options, {});
    const auto log_problem = FixedPointProblem<2>::from_map(
        [](const Vector<2>& x, Vector<2>& g) { g = x + x.array().log().matrix(); }, 2);
    Vector<2> x(-1.0, 2.0);
    const Summary s = engine.solve(log_problem, x);
    EXPECT_EQ(s.status, Status::kNonFinite);
    EXPECT_FALSE(s.usable());
  }
  {  // a budget of 5 evaluations on a problem that needs more
    SolverOptions tight;
    tight.stop.max_evaluations = 5;
    Engine engine(tight, {});
    Vector<2> x(10.0, -10.0);
    const Summary s = engine.solve(squares, x);
    EXPECT_EQ(s.status, Status::kMaxEvaluations);
    EXPECT_LE(s.function_evaluations, 5);
  }
  {  // the same without a Jacobian: forward differences count against the budget too
    SolverOptions tight;
    tight.stop.max_evaluations = 4;
    Engine engine(tight, {});
    const auto no_jacobian = FixedPointProblem<2>::from_map(
        [](const Vector<2>& x, Vector<2>& g) { g = x + x.cwiseProduct(x); }, 2);
    Vector<2> x(10.0, -10.0);
    const Summary s = engine.solve(no_jacobian, x);
    EXPECT_EQ(s.status, Status::kMaxEvaluations);
    EXPECT_LE(s.function_evaluations, 4);
    EXPECT_TRUE(x.allFinite());
    SolverOptions one;
    one.stop.max_evaluations = 1;  // F(x0) only: no room for a Jacobian by differences
    Engine starved(one, {});
    Vector<2> y(10.0, -10.0);
    const Summary t = starved.solve(no_jacobian, y);
    EXPECT_EQ(t.status, Status::kMaxEvaluations);
    EXPECT_EQ(t.function_evaluations, 1);
  }
  {  // forward differences, enough budget: the root of F = x² − 4 from 1 (no AD)
    SolverOptions o;
    o.stop.residual_tolerance = 1e-10;
    Engine engine(o, {});
    const auto shifted = FixedPointProblem<2>::from_map(
        [](const Vector<2>& x, Vector<2>& g) {
          g = x + x.cwiseProduct(x) - Vector<2>::Constant(4.0);
        },
        2);
    Vector<2> x(1.0, 3.0);
    const Summary s = engine.solve(shifted, x);
    EXPECT_EQ(s.status, Status::kConverged) << s.brief_report();
    EXPECT_NEAR(x[0], 2.0, 1e-8);
    EXPECT_NEAR(x[1], 2.0, 1e-8);
  }
  Engine engine(options, {});
  Vector<2> bad(std::nan(""), 1.0);
  EXPECT_THROW(engine.solve(squares, bad), InvalidInput);
  EXPECT_THROW(Engine(options, {.max_backtracks = -1}), InvalidInput);
}

TEST(Plugins, RefusesAPathThatIsNoLoadableLibraryNamingIt) {
  EXPECT_TRUE(
      contains(refusal("/no/such/libplugin.so"), "plugin '/no/such/libplugin.so': no such file"));
  EXPECT_TRUE(contains(refusal(""), "plugin path is empty"));
  EXPECT_TRUE(contains(refusal(NLOBS_PLUGIN_DIR), "is a directory"));
  const fs::path text =
      fs::temp_directory_path() / ("nlobs-not-elf-" + std::to_string(getpid()) + ".so");
  std::ofstream(text) << "not a shared library\n";
  const std::string why = refusal(text.string());
  fs::remove(text);
  EXPECT_TRUE(contains(why, "plugin '" + text.string() + "' cannot be loaded: ")) << why;
}

TEST(Plugins, RefusesALibraryThatIsNotAPluginOrIsBuiltAgainstAnotherNlobs) {
  const std::string not_plugin = test_plugin("test_not_a_plugin");
  EXPECT_TRUE(contains(refusal(not_plugin), "plugin '" + not_plugin +
                                                "' is not an nlobs plugin: it exports no "
                                                "nlobs_plugin_info"))
      << refusal(not_plugin);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"test_plugin_foreign_magic", "is not an nlobs plugin: its nlobs_plugin_info does not"},
      {"test_plugin_null_info", "is not an nlobs plugin: its nlobs_plugin_info does not"},
      {"test_plugin_foreign_layout",
       "was built for nlobs plugin interface 2; this nlobs has "
       "interface 1: rebuild it"},
      {"test_plugin_foreign_version",
       "was built against nlobs '0.0.9'; this is nlobs " + std::string(NLOBS_VERSION_STRING)},
      {"test_plugin_foreign_abi", "was built with 'libc++ abi=1'"}};
  for (const auto& [name, expected] : cases) {
    SCOPED_TRACE(name);
    const std::string why = refusal(test_plugin(name));
    EXPECT_TRUE(contains(why, "plugin '" + test_plugin(name) + "' ")) << why;
    EXPECT_TRUE(contains(why, expected)) << why;
    EXPECT_FALSE(contains(why, "registration")) << why;  // refused before anything of it ran
  }
}

TEST(Plugins, AThrowingRegistrationRegistersNothingAndNamesThePlugin) {
  const std::string path = test_plugin("test_plugin_throwing");
  const std::string why = refusal(path);
  EXPECT_TRUE(contains(why, "plugin '" + path + "' refused: " + path +
                                ": its registration threw: the plugin's configuration file "
                                "is missing (nothing of it was registered)"))
      << why;
  EXPECT_FALSE(EngineRegistry<Dynamic>::global().contains("throwing-plugin-engine"));
}

TEST(Plugins, ATakenNameRefusesTheWholePluginNamingBothSources) {
  // Engines are committed before problem sets: a loader that added as it went would have added
  // the engine before it met the taken set name.
  const std::string path = test_plugin("test_plugin_conflicting");
  const std::string why = refusal(path);
  EXPECT_TRUE(
      contains(why, "problem set 'mgh' from " + path + " is already registered by built-in"))
      << why;
  EXPECT_TRUE(contains(why, "(nothing of " + path + " was registered)")) << why;
  EXPECT_FALSE(EngineRegistry<Dynamic>::global().contains("conflicting-plugin-engine"));
  EXPECT_EQ(problem_set_registry().source("mgh"), "built-in");
}

TEST(Plugins, LoadingAPluginTwiceIsRefusedAndTheFirstStays) {
  load_plugin(kExample);
  const std::string why = refusal(kExample);
  EXPECT_TRUE(contains(why, "from " + kExample + " is already registered by " + kExample)) << why;
  EXPECT_NE(EngineRegistry<Dynamic>::global().create("bad-broyden"), nullptr);
}

TEST(Plugins, ThePluginPathTakesFilesAndDirectories) {
  const fs::path dir = fs::temp_directory_path() / ("nlobs-plugins-" + std::to_string(getpid()));
  fs::create_directories(dir);
  fs::copy_file(kExample, dir / "libexample.so", fs::copy_options::overwrite_existing);
  std::ofstream(dir / "README") << "not a plugin, not a .so: skipped\n";
  const auto loaded = load_plugin_path("::" + dir.string() + ":");
  ASSERT_EQ(loaded.size(), 1u);
  EXPECT_EQ(loaded[0].source, (dir / "libexample.so").string());
  EXPECT_EQ(model_registry().source("fitzhugh-nagumo"), (dir / "libexample.so").string());
  const std::string missing = (dir / "libmissing.so").string();
  try {
    load_plugin_path(missing);
    ADD_FAILURE() << "a missing plugin on the path loaded";
  } catch (const InvalidInput& e) {
    EXPECT_TRUE(contains(e.what(), "plugin '" + missing + "': no such file")) << e.what();
  }
  fs::remove_all(dir);
}

// A program that links its extensions in registers them through the same staging and checks.
TEST(Plugins, AProgramsOwnRegistrationHasTheSameChecks) {
  const auto taken = [](PluginRegistrar& r) {
    r.add_problem_set({.name = "my-set", .problems = [] { return std::vector<TestProblem>{}; }});
    r.add_problem_set({.name = "mgh", .problems = [] { return std::vector<TestProblem>{}; }});
  };
  try {
    register_extensions(taken, "my program");
    ADD_FAILURE() << "a taken name was registered";
  } catch (const InvalidInput& e) {
    EXPECT_TRUE(contains(e.what(),
                         "problem set 'mgh' from my program is already registered by "
                         "built-in (nothing of my program was registered)"))
        << e.what();
  }
  EXPECT_FALSE(problem_set_registry().contains("my-set"));
  const auto twice = [](PluginRegistrar& r) {
    r.add_engine({.name = "mine", .make = [](EngineSpecReader&, SolverOptions o) {
                    return std::unique_ptr<Engine<>>(new example::BadBroydenEngine<>(o, {}));
                  }});
    r.add_engine({.name = "mine", .make = [](EngineSpecReader&, SolverOptions o) {
                    return std::unique_ptr<Engine<>>(new example::BadBroydenEngine<>(o, {}));
                  }});
  };
  try {
    register_extensions(twice, "my program");
    ADD_FAILURE() << "a name registered twice was accepted";
  } catch (const InvalidInput& e) {
    EXPECT_TRUE(contains(e.what(), "engine 'mine' is registered twice by my program")) << e.what();
  }
  const auto bad_name = [](PluginRegistrar& r) {
    r.add_problem_set({.name = "my set", .problems = [] { return std::vector<TestProblem>{}; }});
  };
  try {
    register_extensions(bad_name, "my program");
    ADD_FAILURE() << "a name with a space was accepted";
  } catch (const InvalidInput& e) {
    EXPECT_TRUE(contains(e.what(), "problem set name 'my set' from my program")) << e.what();
  }
  const auto good = [](PluginRegistrar& r) {
    r.add_engine({.name = "mine", .make = [](EngineSpecReader&, SolverOptions o) {
                    return std::unique_ptr<Engine<>>(new example::BadBroydenEngine<>(o, {}));
                  }});
  };
  const LoadedPlugin loaded = register_extensions(good, "my program");
  EXPECT_EQ(loaded.engines, std::vector<std::string>{"mine"});
  EXPECT_EQ(EngineRegistry<Dynamic>::global().source("mine"), "my program");
}

// The CLI: --plugin (before or after the subcommand, repeatable) and NLOBS_PLUGIN_PATH.
using test::CliRun;

CliRun cli(const std::string& environment, const std::string& args) {
  return test::run_shell_command(environment + " " + std::string(NLOBS_CLI_PATH) + " " + args);
}

TEST(Plugins, TheCliLoadsPluginsFromTheCommandLineAndThePath) {
  const CliRun list = cli("", "--plugin " + kExample + " list");
  EXPECT_EQ(list.status, 0) << list.out;
  EXPECT_TRUE(contains(list.out, "fitzhugh-nagumo — FitzHugh-Nagumo neuron")) << list.out;
  EXPECT_TRUE(contains(list.out, "observers: window ekf luenberger sliding_mode mvt high_gain"))
      << list.out;
  EXPECT_TRUE(contains(list.out, "; from " + kExample)) << list.out;
  EXPECT_TRUE(contains(list.out, "bad-broyden — Broyden")) << list.out;
  EXPECT_TRUE(contains(list.out, "example — the example plugin's two problems")) << list.out;

  // After the subcommand, before its arguments: one path per --plugin.
  const CliRun after = cli("", "list --plugin " + kExample + " engines");
  EXPECT_EQ(after.status, 0) << after.out;
  EXPECT_TRUE(contains(after.out, "bad-broyden — Broyden")) << after.out;
  EXPECT_FALSE(contains(after.out, "models (JSON")) << after.out;  // `engines` was the subject
  const CliRun run =
      cli("", "run --plugin " + kExample + " " NLOBS_EXAMPLE_SCENARIO " --steps 300");
  EXPECT_EQ(run.status, 0) << run.out;
  EXPECT_TRUE(contains(run.out, "window:bad-broyden")) << run.out;
  EXPECT_TRUE(contains(run.out, "output_injection")) << run.out;

  const CliRun path = cli("NLOBS_PLUGIN_PATH=" + kExample, "list problems");
  EXPECT_EQ(path.status, 0) << path.out;
  EXPECT_TRUE(contains(path.out, "circle-line:n=2; starts near far; bounded")) << path.out;

  const CliRun solve = cli("", "--plugin " + kExample +
                                   " solve example/circle-line --engines bad-broyden,kinsol:newton "
                                   "--json");
  ASSERT_EQ(solve.status, 0) << solve.out;
  const nlohmann::json rows = nlohmann::json::parse(solve.out);
  ASSERT_EQ(rows.size(), 4u);
  for (const auto& row : rows) EXPECT_TRUE(row["solved"].get<bool>()) << row.dump();

  const CliRun missing = cli("", "--plugin /no/such/plugin.so list");
  EXPECT_EQ(missing.status, 2) << missing.out;
  EXPECT_TRUE(contains(missing.out, "nlobs: error: plugin '/no/such/plugin.so': no such file"))
      << missing.out;
  const CliRun twice = cli("NLOBS_PLUGIN_PATH=" + kExample, "--plugin " + kExample + " list");
  EXPECT_EQ(twice.status, 2) << twice.out;
  EXPECT_TRUE(contains(twice.out, "is already registered by " + kExample)) << twice.out;
}

}  // namespace
}  // namespace nlobs
