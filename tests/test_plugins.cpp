// Plugins: the example plugin (examples/plugin: a model, an engine and a problem set nlobs does
// not ship) loaded at run time works wherever a built-in does — scenarios with the observer
// types its model admits, the suite beside KINSOL and MINPACK, the CLI — and the loader refuses
// every library it must (no file, a directory, not a library, not a plugin, another nlobs, a
// throwing registration, a taken name) with a message naming the plugin, registering nothing.
// ctest runs every test in its own process: each starts with the built-ins only.
#include <elf.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bad_broyden_engine.hpp"
#include "cli_test_files.hpp"
#include "nlobs/common/printable.hpp"
#include "nlobs/models/systems.hpp"
#include "nlobs/reference/problem_suite.hpp"
#include "nlobs/registry/plugin.hpp"
#include "nlobs/runs/scenario.hpp"
#include "plugin_file.hpp"
#include "run_command.hpp"
#include "run_support.hpp"

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

using test::CliRun;

// `nlobs ARGS` run by the shell after `prefix` (variables, `timeout 60`, `true |`).
CliRun cli(const std::string& prefix, const std::string& args) {
  return test::run_shell_command(prefix + " " + std::string(NLOBS_CLI_PATH) + " " + args);
}

TEST(Plugins, TheExamplePluginRegistersOneEntryOfEachKind) {
  const LoadedPlugin loaded = load_plugin(kExample);
  EXPECT_EQ(loaded.source, kExample);
  EXPECT_EQ(loaded.models, std::vector<std::string>{"fitzhugh-nagumo"});
  EXPECT_EQ(loaded.engines, std::vector<std::string>{"bad-broyden"});
  EXPECT_EQ(loaded.problem_sets, std::vector<std::string>{"example"});
  EXPECT_EQ(loaded.observer_types,
            (std::vector<std::string>{"output_injection", "fixed_size_ekf"}));
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
  const Scenario s = parse_scenario(json, NLOBS_EXAMPLE_SCENARIO);
  const ModelInstance model = scenario_model(s);
  const Measurements data = simulate_scenario(s, model.discrete);
  auto observers = make_observers(s, model, false);
  const RunResult r = run_observers(data, observers, 200);  // after 10 s, the settle time
  ASSERT_EQ(r.metrics.size(), 7u);
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
  // The plugin's model-typed EKF (fixed-size matrices, the model's own type) is the built-in
  // EKF's arithmetic on the same covariances: the same estimates to rounding.
  EXPECT_EQ(r.metrics[6].name, "fixed_size_ekf");
  EXPECT_EQ(r.estimates[6].cols(), r.estimates[2].cols());
  EXPECT_LT((r.estimates[6] - r.estimates[2]).cwiseAbs().maxCoeff(), 1e-9);
  // The modulating observer needs a canonical form the model does not supply: named.
  nlohmann::json modulating = json;
  modulating["observers"] = nlohmann::json::parse(R"([{"type": "modulating"}])");
  try {
    const Scenario m = parse_scenario(modulating, "modulating");
    make_observers(m, scenario_model(m), false);
    ADD_FAILURE() << "the modulating observer accepted a model without a canonical form";
  } catch (const std::exception& e) {
    EXPECT_TRUE(contains(e.what(), "modulating on model 'fitzhugh-nagumo': no canonical form"))
        << e.what();
  }
}

// A model-typed observer type from a plugin reaches the model's C++ type for the types it was
// built for — its own model and a built-in one — and is refused by name on any other.
TEST(Plugins, APluginObserverTypeBuiltOnTheModelsOwnTypeTakesTheTypesItKnows) {
  load_plugin(kExample);
  const auto scenario = [](const std::string& model, int n) {
    nlohmann::json j = {{"name", "typed"},
                        {"model", {{"name", model}}},
                        {"x0", std::vector<double>(n, 1.0)},
                        {"initial_guess", std::vector<double>(n, 0.5)},
                        {"steps", 300},
                        {"observers", nlohmann::json::array()}};
    j["observers"].push_back({{"type", "ekf"}, {"process_covariance", 1e-6}});
    j["observers"].push_back({{"type", "fixed_size_ekf"}, {"process_covariance", 1e-6}});
    return parse_scenario(j, "typed " + model);
  };
  const Scenario lorenz = scenario("lorenz", 3);
  const ModelInstance model = scenario_model(lorenz);
  ASSERT_NE(model.model_as<Lorenz>(), nullptr);
  EXPECT_EQ(model.model_as<Duffing>(), nullptr);
  const Measurements data = simulate_scenario(lorenz, model.discrete);
  auto observers = make_observers(lorenz, model, false);
  const RunResult r = run_observers(data, observers);
  ASSERT_EQ(r.estimates.size(), 2u);
  ASSERT_TRUE(r.estimates[1].allFinite());
  // A chaotic system: the two filters agree to rounding only over the first hundred samples.
  const Eigen::Index head = 100;
  EXPECT_LT((r.estimates[1].leftCols(head) - r.estimates[0].leftCols(head)).cwiseAbs().maxCoeff(),
            1e-6);
  try {
    const Scenario duffing = scenario("duffing", 2);
    make_observers(duffing, scenario_model(duffing), false);
    ADD_FAILURE() << "fixed_size_ekf accepted a model type it was not built for";
  } catch (const std::exception& e) {  // the scenario's refusal, naming the observer's place
    EXPECT_TRUE(contains(e.what(),
                         "fixed_size_ekf on model 'duffing': it is built for "
                         "fitzhugh-nagumo and lorenz only"))
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
    Engine engine({}, options);
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
    Engine engine({}, options);
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
    Engine engine({}, options);
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
    Engine engine({}, tight);
    Vector<2> x(10.0, -10.0);
    const Summary s = engine.solve(squares, x);
    EXPECT_EQ(s.status, Status::kMaxEvaluations);
    EXPECT_LE(s.function_evaluations, 5);
  }
  {  // the same without a Jacobian: forward differences count against the budget too
    SolverOptions tight;
    tight.stop.max_evaluations = 4;
    Engine engine({}, tight);
    const auto no_jacobian = FixedPointProblem<2>::from_map(
        [](const Vector<2>& x, Vector<2>& g) { g = x + x.cwiseProduct(x); }, 2);
    Vector<2> x(10.0, -10.0);
    const Summary s = engine.solve(no_jacobian, x);
    EXPECT_EQ(s.status, Status::kMaxEvaluations);
    EXPECT_LE(s.function_evaluations, 4);
    EXPECT_TRUE(x.allFinite());
    SolverOptions one;
    one.stop.max_evaluations = 1;  // F(x0) only: no room for a Jacobian by differences
    Engine starved({}, one);
    Vector<2> y(10.0, -10.0);
    const Summary t = starved.solve(no_jacobian, y);
    EXPECT_EQ(t.status, Status::kMaxEvaluations);
    EXPECT_EQ(t.function_evaluations, 1);
  }
  {  // forward differences, enough budget: the root of F = x² − 4 from 1 (no AD)
    SolverOptions o;
    o.stop.residual_tolerance = 1e-10;
    Engine engine({}, o);
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
  Engine engine({}, options);
  Vector<2> bad(std::nan(""), 1.0);
  EXPECT_THROW(engine.solve(squares, bad), InvalidInput);
  EXPECT_THROW(Engine({.max_backtracks = -1}, options), InvalidInput);
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
       "was built for nlobs plugin interface " + std::to_string(kPluginLayout + 1) +
           "; this nlobs has interface " + std::to_string(kPluginLayout) + ": rebuild it"},
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
                    return std::unique_ptr<Engine<>>(new example::BadBroydenEngine<>({}, o));
                  }});
    r.add_engine({.name = "mine", .make = [](EngineSpecReader&, SolverOptions o) {
                    return std::unique_ptr<Engine<>>(new example::BadBroydenEngine<>({}, o));
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
                    return std::unique_ptr<Engine<>>(new example::BadBroydenEngine<>({}, o));
                  }});
  };
  const LoadedPlugin loaded = register_extensions(good, "my program");
  EXPECT_EQ(loaded.engines, std::vector<std::string>{"mine"});
  EXPECT_EQ(EngineRegistry<Dynamic>::global().source("mine"), "my program");
}

// A fresh scratch directory for one test, removed when the test ends.
struct Scratch {
  fs::path dir;
  explicit Scratch(const std::string& name)
      : dir(fs::temp_directory_path() / ("nlobs-" + name + "-" + std::to_string(getpid()))) {
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  ~Scratch() { fs::remove_all(dir); }
  std::string write(const std::string& name, const std::string& bytes) const {
    std::ofstream(dir / name, std::ios::binary) << bytes;
    return (dir / name).string();
  }
};

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

bool has_control_character(const std::string& text) {
  for (const char c : text) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7F) return true;
  }
  return false;
}

// dlopen on a FIFO blocks until a writer comes; on a device it reads what the device gives.
// The loader refuses both by the file's type (stat: through links) before opening anything.
TEST(Plugins, RefusesAFifoADeviceAndASocketByName) {
  const Scratch scratch("special");
  const fs::path fifo = scratch.dir / "libfifo.so";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
  // A writer holding it open with bytes waiting, as a producer would: a loader that opened the
  // FIFO would read them and then wait for more (this test then times out: measured with the
  // loader before the type check).
  const int writer = open(fifo.c_str(), O_RDWR | O_NONBLOCK);
  ASSERT_GE(writer, 0);
  ASSERT_EQ(write(writer, "not a library", 13), 13);
  std::string why = refusal(fifo.string());
  EXPECT_EQ(why, "plugin '" + fifo.string() + "' is a FIFO, not a shared library");
  const fs::path link = scratch.dir / "liblink.so";
  fs::create_symlink(fifo, link);
  why = refusal(link.string());
  EXPECT_EQ(why, "plugin '" + link.string() + "' is a FIFO, not a shared library");
  close(writer);

  EXPECT_EQ(refusal("/dev/null"), "plugin '/dev/null' is a character device, not a shared library");

  const fs::path socket_path = scratch.dir / "libsocket.so";
  const int server = socket(AF_UNIX, SOCK_STREAM, 0);
  ASSERT_GE(server, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  ASSERT_LT(socket_path.string().size(), sizeof(address.sun_path));
  std::strcpy(address.sun_path, socket_path.c_str());
  ASSERT_EQ(bind(server, reinterpret_cast<const sockaddr*>(&address), sizeof(address)), 0);
  why = refusal(socket_path.string());
  close(server);
  EXPECT_EQ(why, "plugin '" + socket_path.string() + "' is a socket, not a shared library");
}

// The CLI with a FIFO where a plugin is expected: as --plugin, as /dev/stdin on a pipe, as a
// *.so in a NLOBS_PLUGIN_PATH directory. `timeout` turns a loader that waits into a failure.
TEST(Plugins, TheCliRefusesAFifoInsteadOfWaitingForAWriter) {
  const Scratch scratch("cli-fifo");
  const fs::path fifo = scratch.dir / "libfifo.so";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
  const CliRun given = cli("timeout 60", "--plugin " + fifo.string() + " list");
  EXPECT_EQ(given.status, 2) << given.out;
  EXPECT_TRUE(contains(
      given.out, "nlobs: error: plugin '" + fifo.string() + "' is a FIFO, not a shared library"))
      << given.out;
  // /dev/stdin of `true | nlobs`: a pipe whose writer has gone.
  const CliRun stdin_pipe = cli("true | timeout 60", "--plugin /dev/stdin list");
  EXPECT_EQ(stdin_pipe.status, 2) << stdin_pipe.out;
  EXPECT_TRUE(contains(stdin_pipe.out, "plugin '/dev/stdin' is a FIFO, not a shared library"))
      << stdin_pipe.out;
  // On the path, the FIFO is refused by name, not skipped (a plugin put there would otherwise
  // go missing without a word); the library beside it sorts after it and is not reached.
  fs::copy_file(kExample, scratch.dir / "libz_example.so");
  const CliRun path = cli("NLOBS_PLUGIN_PATH=" + scratch.dir.string() + " timeout 60", "list");
  EXPECT_EQ(path.status, 2) << path.out;
  EXPECT_TRUE(contains(path.out, "plugin '" + fifo.string() + "' is a FIFO, not a shared library"))
      << path.out;
}

// An interrupted copy: dlopen maps segments past the end of the file and dies of SIGBUS when it
// touches them. The loader reads the ELF headers first and refuses, at every length.
TEST(Plugins, ATruncatedLibraryIsRefusedByNameAtEveryLength) {
  const Scratch scratch("truncated");
  const std::string library = file_bytes(kExample);
  ASSERT_GT(library.size(), 10000u);
  const std::size_t half = library.size() / 2;
  for (const std::size_t size :
       {std::size_t{1}, std::size_t{4}, std::size_t{63}, std::size_t{64}, std::size_t{200},
        std::size_t{4096}, half, library.size() - 4096, library.size() - 1}) {
    SCOPED_TRACE(size);
    const std::string path = scratch.write("libcut.so", library.substr(0, size));
    const std::string why = refusal(path);
    EXPECT_TRUE(contains(why, "plugin '" + path + "' cannot be loaded: it is truncated: ")) << why;
    EXPECT_TRUE(size < 64 || contains(why, " of a " + std::to_string(size) + "-byte file")) << why;
  }
  // Cut inside the last loadable segment (read from the file's own program headers: in a
  // Debug build the debug sections make up most of the file, so half of it may hold every
  // segment): a loadable segment reaches past the cut.
  Elf64_Ehdr header;
  std::memcpy(&header, library.data(), sizeof header);
  std::size_t segments_end = 0;
  for (int i = 0; i < header.e_phnum; ++i) {
    Elf64_Phdr segment;
    std::memcpy(&segment, library.data() + header.e_phoff + i * std::size_t{header.e_phentsize},
                sizeof segment);
    if (segment.p_type == PT_LOAD && segment.p_filesz > 0) {
      segments_end = std::max<std::size_t>(segments_end, segment.p_offset + segment.p_filesz);
    }
  }
  ASSERT_GT(segments_end, 64u);
  const std::size_t inside = segments_end - 1;
  const std::string path = scratch.write("libhalf.so", library.substr(0, inside));
  const std::string why = refusal(path);
  EXPECT_TRUE(contains(why, "it is truncated: its program header ")) << why;
  EXPECT_TRUE(contains(why, " of a " + std::to_string(inside) + "-byte file")) << why;
  // The last byte missing: the section header table ends the file.
  const std::string short_path =
      scratch.write("libshort.so", library.substr(0, library.size() - 1));
  const std::string short_why = refusal(short_path);
  EXPECT_TRUE(contains(short_why, "it is truncated: its section header table ends at byte " +
                                      std::to_string(library.size()) + " of a " +
                                      std::to_string(library.size() - 1) + "-byte file"))
      << short_why;
  const std::string header_why = refusal(scratch.write("libheader.so", library.substr(0, 63)));
  EXPECT_TRUE(contains(header_why, "its ELF header needs 64 bytes, the file has 63")) << header_why;
  EXPECT_FALSE(model_registry().contains("fitzhugh-nagumo"));
  // The whole copy passes the same checks and loads.
  const std::string whole = scratch.write("libwhole.so", library);
  EXPECT_EQ(load_plugin(whole).models, std::vector<std::string>{"fitzhugh-nagumo"});
}

// Files that are no shared library for this nlobs, each refused by what is wrong with it.
TEST(Plugins, AFileThatIsNoLibraryForThisHostIsRefusedByWhatItIs) {
  const Scratch scratch("not-library");
  const std::string library = file_bytes(kExample);
  ASSERT_GE(library.size(), sizeof(Elf64_Ehdr));
  const auto refused = [&](const std::string& bytes) {
    return refusal(scratch.write("libx.so", bytes));
  };
  const std::string prefix = "cannot be loaded: it ";
  EXPECT_TRUE(contains(refused(""), prefix + "is empty")) << refused("");
  EXPECT_TRUE(contains(refused("not a shared library\n"), prefix + "is not an ELF file"));
  // A header changed field by field (native byte order: this build's).
  const auto changed = [&](auto change) {
    std::string bytes = library;
    Elf64_Ehdr header;
    std::memcpy(&header, bytes.data(), sizeof(header));
    change(header);
    std::memcpy(bytes.data(), &header, sizeof(header));
    return refused(bytes);
  };
  std::string why = changed([](Elf64_Ehdr& h) { h.e_ident[EI_CLASS] = ELFCLASS32; });
  EXPECT_TRUE(contains(why, prefix + "is a 32-bit ELF file; this nlobs is 64-bit")) << why;
  why = changed([](Elf64_Ehdr& h) { h.e_ident[EI_DATA] = ELFDATA2MSB; });
  EXPECT_TRUE(contains(why, prefix + "is big-endian; this machine is little-endian")) << why;
  why = changed([](Elf64_Ehdr& h) { h.e_machine = EM_S390; });
  EXPECT_TRUE(contains(why, prefix + "is built for s390; this nlobs runs on ")) << why;
  why = changed([](Elf64_Ehdr& h) { h.e_type = ET_EXEC; });
  EXPECT_TRUE(contains(why, prefix + "is not a shared library: it is an executable")) << why;
  why = changed([](Elf64_Ehdr& h) { h.e_type = ET_REL; });
  EXPECT_TRUE(contains(why, prefix + "is not a shared library: it is a relocatable object")) << why;
  why = changed([](Elf64_Ehdr& h) { h.e_phentsize = 32; });
  EXPECT_TRUE(contains(why, prefix + "has program headers of 32 bytes, not 56")) << why;
  // Tables beyond any file: their ends are computed without wrapping around.
  why = changed([](Elf64_Ehdr& h) { h.e_phoff = ~Elf64_Off{0} - 8; });
  EXPECT_TRUE(
      contains(why, prefix + "is truncated: its program header table ends beyond byte 2^64"))
      << why;
  why = changed([](Elf64_Ehdr& h) { h.e_shoff = ~Elf64_Off{0}; });
  EXPECT_TRUE(
      contains(why, prefix + "is truncated: its section header table ends beyond byte 2^64"))
      << why;
  EXPECT_FALSE(model_registry().contains("fitzhugh-nagumo"));
}

// The seeds of fuzz_plugin_file (tests/fuzz/make_plugin_file_corpus.py) get the verdicts they
// were written for: the checks accept a well-formed file, extended numbering included, and
// name what is wrong with each damaged one.
TEST(Plugins, TheElfChecksGiveTheFuzzSeedsTheirVerdicts) {
  if (plugin_file::detail::kHostMachine != EM_X86_64) GTEST_SKIP() << "the seeds are x86-64";
  const std::vector<std::pair<std::string, std::string>> seeds = {
      {"minimal.so", ""},
      {"extended_numbering.so", ""},
      {"header_only.so", ""},
      {"truncated_header.so", "is truncated: its ELF header needs 64 bytes, the file has 40"},
      {"truncated_segment.so",
       "is truncated: its program header 0 ends at byte 65536 of a "
       "384-byte file"},
      {"truncated_sections.so",
       "is truncated: its section header table ends at byte 384 of a "
       "383-byte file"},
      {"executable.so", "is not a shared library: it is an executable"},
      {"elf32.so", "is a 32-bit ELF file; this nlobs is 64-bit"},
      {"big_endian.so", "is big-endian; this machine is little-endian"},
      {"text.so", "is not an ELF file (a shared library starts with \\x7fELF)"}};
  for (const auto& [name, expected] : seeds) {
    SCOPED_TRACE(name);
    const std::string bytes = file_bytes(std::string(NLOBS_PLUGIN_FILE_CORPUS) + "/" + name);
    ASSERT_FALSE(bytes.empty());
    EXPECT_EQ(plugin_file::elf_problem(bytes), expected);
  }
}

// An engine entry of the given name (the example's Broyden engine).
EngineRegistry<Dynamic>::Entry engine_named(const std::string& name) {
  return {.name = name, .make = [](EngineSpecReader&, SolverOptions o) {
            return std::unique_ptr<Engine<>>(new example::BadBroydenEngine<>({}, o));
          }};
}

// What the captureless registration below stages (PluginRegistration is a function pointer).
std::string staged_name;

// One name rule for models, observer types, engines and problem sets (registry_name.hpp):
// 1 to 64 of [A-Za-z0-9_.+-], refused by name with the name made printable, wherever it is
// added: through a plugin's registrar or a registry's own add.
TEST(Plugins, OneNameRuleForEveryRegistryBoundedAndPrintable) {
  const std::string longest(64, 'n');
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"", "is empty"},
      {"line\nbreak", "'line\\x0abreak' from my program has '\\x0a' at byte 5"},
      {"\x1b[31mred", "'\\x1b[31mred' from my program has '\\x1b' at byte 1"},
      {"tab\there", "has '\\x09' at byte 4"},
      {"bell\a", "has '\\x07' at byte 5"},
      {"quote'd", "has ''' at byte 6"},
      {"\"quoted\"", "has '\"' at byte 1"},
      {"my engine", "has ' ' at byte 3"},
      {"anderson:m=3", "has ':' at byte 9"},
      {"a,b", "has ',' at byte 2"},
      {"a=b", "has '=' at byte 2"},
      {"set/name", "has '/' at byte 4"},
      {"caf\xc3\xa9", "has '\\xc3' at byte 4"},
      {longest + "n", "has 65 bytes, more than 64"},
      {std::string(10000, 'x'), "has 10000 bytes, more than 64"}};
  for (const auto& [name, expected] : bad) {
    SCOPED_TRACE(printable(name, 40));
    staged_name = name;
    const auto stage_engine = [](PluginRegistrar& r) { r.add_engine(engine_named(staged_name)); };
    std::string why;
    try {
      register_extensions(stage_engine, "my program");
      ADD_FAILURE() << "a bad engine name was registered";
    } catch (const InvalidInput& e) {
      why = e.what();
    }
    EXPECT_TRUE(contains(why, "engine name '")) << why;
    EXPECT_TRUE(contains(why, expected)) << why;
    EXPECT_TRUE(contains(why, "(a name is 1 to 64 characters: ASCII letters, digits and _ . + -)"))
        << why;
    EXPECT_FALSE(has_control_character(why)) << why;
    EXPECT_LT(why.size(), 300u) << why;  // the name is cut at 60 bytes
    // The registries' own add() applies the same rule.
    try {
      EngineRegistry<Dynamic>::global().add(engine_named(name), "my program");
      ADD_FAILURE() << "EngineRegistry::add took a bad name";
    } catch (const InvalidInput& e) {
      EXPECT_TRUE(contains(e.what(), expected)) << e.what();
      EXPECT_FALSE(has_control_character(e.what())) << e.what();
    }
    try {
      problem_set_registry().add(
          {.name = name, .problems = [] { return std::vector<TestProblem>{}; }}, "my program");
      ADD_FAILURE() << "NamedRegistry::add took a bad name";
    } catch (const InvalidInput& e) {
      EXPECT_TRUE(contains(e.what(), "problem set name '")) << e.what();
      EXPECT_TRUE(contains(e.what(), expected)) << e.what();
      EXPECT_FALSE(has_control_character(e.what())) << e.what();
    }
  }
  // 64 characters, and every kind of character the rule allows, make names.
  const auto good = [](PluginRegistrar& r) {
    r.add_engine(engine_named(std::string(64, 'n')));
    r.add_engine(engine_named("Az09_.+-"));
    r.add_problem_set(
        {.name = std::string(64, 'n'), .problems = [] { return std::vector<TestProblem>{}; }});
  };
  const LoadedPlugin loaded = register_extensions(good, "my program");
  EXPECT_EQ(loaded.engines, (std::vector<std::string>{longest, "Az09_.+-"}));
  EXPECT_TRUE(problem_set_registry().contains(longest));
}

// What the loader echoes of a user's or a plugin's text goes through printable(): a path with
// a line break or a terminal escape, dlopen's message (which repeats the path), a registration's
// exception text of any type, a program's source name.
TEST(Plugins, PathsAndExceptionTextsAreEchoedPrintable) {
  const Scratch scratch("echo");
  const fs::path evil = scratch.dir / "dir\nnlobs: fake line \x1b[2J";
  fs::create_directories(evil);
  const std::string shown = printable((evil / "libthrowing.so").string());
  EXPECT_TRUE(contains(shown, "dir\\x0anlobs: fake line \\x1b[2J")) << shown;
  // The throwing plugin: the path twice (the plugin, the source of its registration).
  fs::copy_file(test_plugin("test_plugin_throwing"), evil / "libthrowing.so");
  std::string why = refusal((evil / "libthrowing.so").string());
  EXPECT_FALSE(has_control_character(why)) << why;
  EXPECT_TRUE(
      contains(why, "plugin '" + shown + "' refused: " + shown + ": its registration threw"))
      << why;
  // An ELF header alone passes the file checks and reaches dlopen, whose message names the path.
  std::string header = file_bytes(kExample).substr(0, sizeof(Elf64_Ehdr));
  Elf64_Ehdr h;
  std::memcpy(&h, header.data(), sizeof(h));
  h.e_phnum = 0;
  h.e_shnum = 0;
  h.e_shoff = 0;
  std::memcpy(header.data(), &h, sizeof(h));
  std::ofstream(evil / "libheader.so", std::ios::binary) << header;
  why = refusal((evil / "libheader.so").string());
  EXPECT_TRUE(contains(why, "cannot be loaded: ")) << why;
  EXPECT_TRUE(contains(why, "fake line \\x1b[2J/libheader.so: ")) << why;  // dlopen's message
  EXPECT_FALSE(has_control_character(why)) << why;
  // A missing file and a directory, named printable as well.
  why = refusal((evil / "libmissing.so").string());
  EXPECT_TRUE(contains(why, ": no such file")) << why;
  EXPECT_FALSE(has_control_character(why)) << why;
  EXPECT_FALSE(has_control_character(refusal(evil.string())));

  // Exceptions of a program's registration: any text, any type.
  const auto throws_text = [](PluginRegistrar&) {
    throw std::runtime_error("bad\nnlobs: error: forged\x1b[0m");
  };
  try {
    register_extensions(throws_text, "my\nprogram");
    ADD_FAILURE() << "a throwing registration was accepted";
  } catch (const InvalidInput& e) {
    EXPECT_EQ(
        std::string(e.what()),
        "my\\x0aprogram: its registration threw: bad\\x0anlobs: error: forged\\x1b[0m (nothing of "
        "it was registered)");
  }
  const auto throws_int = [](PluginRegistrar&) { throw 42; };
  try {
    register_extensions(throws_int, "my program");
    ADD_FAILURE() << "a throwing registration was accepted";
  } catch (const InvalidInput& e) {
    EXPECT_EQ(std::string(e.what()),
              "my program: its registration threw: a non-standard exception (nothing of it was "
              "registered)");
  }
  // The source a registry keeps is the printable one (`nlobs list` prints it).
  const auto good = [](PluginRegistrar& r) {
    r.add_problem_set({.name = "echo-set", .problems = [] { return std::vector<TestProblem>{}; }});
  };
  EXPECT_EQ(register_extensions(good, "my\x1b]0;title\a program").source,
            "my\\x1b]0;title\\x07 program");
  EXPECT_EQ(problem_set_registry().source("echo-set"), "my\\x1b]0;title\\x07 program");
}

// The CLI: --plugin (before or after the subcommand, repeatable) and NLOBS_PLUGIN_PATH.

TEST(Plugins, TheCliLoadsPluginsFromTheCommandLineAndThePath) {
  const CliRun list = cli("", "--plugin " + kExample + " list");
  EXPECT_EQ(list.status, 0) << list.out;
  EXPECT_TRUE(contains(list.out, "fitzhugh-nagumo — FitzHugh-Nagumo neuron")) << list.out;
  EXPECT_TRUE(
      contains(list.out, "observers: window ekf ukf mhe luenberger sliding_mode mvt high_gain"))
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
