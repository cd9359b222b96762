// `nlobs run`: the chua-fp experiment's claims, the output contract, scenario files and
// recorded data, and every bad input the issue lists.
#include <csv.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "cli_test_files.hpp"
#include "gnuplot.hpp"
#include "nlobs/models/discretization.hpp"
#include "nlobs/models/systems.hpp"
#include "nlobs/observers/core/simulation.hpp"
#include "nlobs/observers/pi/pi_bound.hpp"
#include "nlobs/runs/scenario.hpp"
#include "run_command.hpp"
#include "run_support.hpp"
#include "short_tests.hpp"

namespace nlobs::cli {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  return test::scratch_path("nlobs_test_run", name);
}

std::string error_of(const std::string& scenario, const RunOptions& o = {}) {
  std::ostringstream out, err;
  try {
    run_scenario(scenario, o, out, err);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "<no error>";
}

void write(const fs::path& p, const std::string& text) {
  test::write_file(p, text);
}

// Every record of a CSV file as parsed by libcsv in strict RFC 4180 mode (not our reader).
std::vector<std::vector<std::string>> csv_records(const fs::path& p) {
  struct Parsed {
    std::vector<std::vector<std::string>> records{{}};
  } parsed;
  csv_parser parser;
  EXPECT_EQ(csv_init(&parser, CSV_STRICT | CSV_STRICT_FINI), 0);
  csv_set_space_func(&parser, [](unsigned char) { return 0; });  // RFC 4180 keeps spaces
  std::ifstream in(p, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto on_field = [](void* field, size_t length, void* data) {
    static_cast<Parsed*>(data)->records.back().emplace_back(static_cast<const char*>(field),
                                                            length);
  };
  const auto on_record = [](int, void* data) {
    static_cast<Parsed*>(data)->records.emplace_back();
  };
  EXPECT_EQ(csv_parse(&parser, text.data(), text.size(), on_field, on_record, &parsed), text.size())
      << csv_strerror(csv_error(&parser));
  EXPECT_EQ(csv_fini(&parser, on_field, on_record, &parsed), 0) << p;
  csv_free(&parser);
  if (parsed.records.back().empty()) parsed.records.pop_back();
  return parsed.records;
}

TEST(Run, ChuaFpReproducesThePapersClaims) {
  const fs::path dir = scratch("chua-fp");
  std::ostringstream out, err;
  run_scenario("chua-fp", {.out_dir = dir.string()}, out, err);
  const std::string table = out.str();
  EXPECT_NE(table.find("paper MSE"), std::string::npos);
  EXPECT_NE(table.find("0.3335"), std::string::npos);  // the paper's Luenberger MSE beside ours

  std::ifstream in(dir / "summary.json");
  const auto summary = nlohmann::json::parse(in);
  for (const char* key : {"scenario", "steps", "noise_std", "seed", "observers"}) {
    ASSERT_TRUE(summary.contains(key)) << key;
  }
  EXPECT_EQ(summary["scenario"], "chua-fp");
  std::map<std::string, nlohmann::json> by_name;
  for (const auto& o : summary["observers"]) {
    for (const char* key :
         {"name", "engine", "mse", "mse_after_window", "iterations_mean", "iterations_max",
          "first_window_iterations", "evaluations_mean", "ns_per_step", "failures"}) {
      ASSERT_TRUE(o.contains(key)) << key << " in " << o.dump();
    }
    by_name[o["name"]] = o;
  }
  auto mean_after = [&](const std::string& n) {
    double s = 0;
    for (const auto& v : by_name.at(n)["mse_after_window"]) s += v.get<double>();
    return s / 3.0;
  };
  // After the window fills, window estimators are far below Luenberger and sliding mode.
  for (const char* w : {"window:picard", "window:aitken", "window:steffensen", "window:anderson",
                        "window:newton", "window:ceres,N=6"}) {
    EXPECT_LT(1e3 * mean_after(w), mean_after("luenberger")) << w;
    EXPECT_LT(1e3 * mean_after(w), mean_after("sliding_mode")) << w;
  }
  const auto first = [&](const std::string& n) {
    return by_name.at(n)["first_window_iterations"].get<int>();
  };
  EXPECT_GT(first("window:picard"), first("window:aitken"));
  EXPECT_GT(first("window:aitken"), first("window:steffensen"));
  EXPECT_LE(first("window:newton"), 5);
  for (const char* f : {"trajectories.csv", "scenario.json", "first_window.dat"}) {
    EXPECT_TRUE(fs::exists(dir / f)) << f;
  }
  // The convergence plot's data: each window observer's first-window trace, one line per
  // iteration (ceres records none: docs/solvers.md).
  std::map<std::string, int> traced;
  std::ifstream first_window(dir / "first_window.dat");
  for (std::string line; std::getline(first_window, line);) {
    if (!line.empty() && line[0] != '#') ++traced[line.substr(0, line.find(' '))];
  }
  for (const char* n : {"window:picard", "window:aitken", "window:newton"}) {
    EXPECT_EQ(traced[n], first(n)) << n;
  }
  for (const auto& entry : fs::directory_iterator(dir)) {
    // Nothing half-written (temporaries: `.NAME.tmp-XXXXXX`).
    EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos) << entry.path();
  }
  std::ifstream csv(dir / "trajectories.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header.rfind("t,x1,x2,x3,window:picard.x1", 0), 0U) << header;
  // RFC 4180: "window:ceres,N=6.x1" is one quoted field, so every row has the header's fields.
  const auto records = csv_records(dir / "trajectories.csv");
  ASSERT_GT(records.size(), 2u);
  const std::vector<std::string>& names = records.front();
  EXPECT_NE(std::find(names.begin(), names.end(), "window:ceres,N=6.x1"), names.end()) << header;
  EXPECT_EQ(names.size(), 1u + 3u + 9u * 3u);  // t, the truth, nine observers' estimates
  for (size_t k = 1; k < records.size(); ++k) {
    ASSERT_EQ(records[k].size(), names.size()) << "row " << k;
  }
}

TEST(Run, ScenarioJsonRoundTrip) {
  const Scenario s = load_scenario("chua-fp");
  const nlohmann::json j = to_json(s);
  const Scenario back = parse_scenario(j, "round trip");
  EXPECT_EQ(to_json(back), j);
  EXPECT_EQ(back.observers.size(), s.observers.size());
  EXPECT_EQ(observer_spec_json(back.observers[5])["window"], 6);
  EXPECT_EQ(back.reported.at("luenberger").at("mse"), 0.3335);
}

TEST(Run, ScenarioFileErrorsNameTheFileAndKey) {
  const fs::path f = scratch("bad.json");
  nlohmann::json j = to_json(load_scenario("chua-fp"));
  j["stpes"] = 10;
  write(f, j.dump());
  std::string e = error_of(f.string());
  EXPECT_NE(e.find(f.string()), std::string::npos) << e;
  EXPECT_NE(e.find("unknown key 'stpes'"), std::string::npos) << e;

  j = to_json(load_scenario("chua-fp"));
  j["observers"][1]["tol"] = "small";
  write(f, j.dump());
  e = error_of(f.string());
  EXPECT_NE(e.find("observers[1]"), std::string::npos) << e;
  EXPECT_NE(e.find("'tol' must be a finite number"), std::string::npos) << e;

  j = to_json(load_scenario("chua-fp"));
  j.erase("x0");
  write(f, j.dump());
  EXPECT_NE(error_of(f.string()).find("missing field 'x0'"), std::string::npos);

  j = to_json(load_scenario("chua-fp"));
  j["model"]["name"] = "chua-ish";
  write(f, j.dump());
  e = error_of(f.string());
  EXPECT_NE(e.find("unknown model 'chua-ish'"), std::string::npos) << e;
  EXPECT_NE(e.find("lorenz"), std::string::npos) << e;

  j = to_json(load_scenario("chua-fp"));
  j["observers"][0]["engine"] = "picard:m=3";
  write(f, j.dump());
  EXPECT_NE(error_of(f.string()).find("unknown option(s) 'm'"), std::string::npos);

  write(f, "{ not json");
  EXPECT_NE(error_of(f.string()).find("not valid JSON"), std::string::npos);
  EXPECT_NE(error_of("no-such-scenario").find("neither a built-in scenario"), std::string::npos);
}

// Issue "estimates that never lock onto a wrong answer": Ψ from the scenario file, the
// warnings a run finds, and failures that are never silent in the table and summary.json.
TEST(Run, PsiRoundTripsAndBadValuesNameTheKey) {
  nlohmann::json j = to_json(load_scenario("chua-fp"));
  j["observers"][0]["psi"] = "newton";
  j["observers"][1]["psi"] = 0.5;
  const Scenario s = parse_scenario(j, "psi");
  EXPECT_EQ(observer_spec_json(s.observers[0])["psi"], "newton");
  EXPECT_TRUE(observer_spec_json(s.observers[1])["psi"].is_number());
  EXPECT_EQ(observer_spec_json(s.observers[1])["psi"], 0.5);
  EXPECT_EQ(to_json(s), j);
  const fs::path f = scratch("psi.json");
  for (const nlohmann::json& bad : {nlohmann::json("chord"), nlohmann::json(0.0)}) {
    j["observers"][1]["psi"] = bad;
    write(f, j.dump());
    const std::string e = error_of(f.string());
    EXPECT_NE(e.find("observers[1]"), std::string::npos) << e;
    EXPECT_NE(e.find("'psi'"), std::string::npos) << e;
  }
}

TEST(Run, FailuresAndWarningsAreReported) {
  // Lorenz from its equilibrium: the newton window warns of the singular guess; Picard with
  // Ψ = I stagnates; an unstable Luenberger gain overflows. None of it is silent.
  const fs::path f = scratch("failing.json");
  write(f, R"({"name": "failing", "model": {"name": "lorenz", "scheme": "rk4", "step": 0.01},
    "x0": [1, 1, 1], "initial_guess": [0, 0, 0], "steps": 300, "noise": 0.01, "seed": 7,
    "observers": [{"type": "window", "engine": "newton", "tol": 1e-8},
                  {"type": "window", "engine": "picard", "tol": 1e-8, "psi": 0.5},
                  {"type": "luenberger", "gain": [[5], [3], [1]]}]})");
  std::ostringstream out, err;
  const fs::path dir = scratch("failing_out");
  RunOptions o;
  o.out_dir = dir.string();
  run_scenario(f.string(), o, out, err);
  EXPECT_NE(err.str().find("singular point of the window map"), std::string::npos) << err.str();
  EXPECT_NE(out.str().find("first failure of window:picard: k = 2"), std::string::npos)
      << out.str();
  EXPECT_NE(out.str().find("first failure of luenberger"), std::string::npos) << out.str();
  std::ifstream in(dir / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(in);
  bool warned = false;
  for (const auto& w : summary["warnings"]) {
    warned = warned || w.get<std::string>().find("singular point") != std::string::npos;
  }
  EXPECT_TRUE(warned) << summary["warnings"];
  const auto& luenberger = summary["observers"][2];
  EXPECT_GT(luenberger["failures"]["non_finite_estimate"].get<int>(), 100);
  EXPECT_NE(luenberger["first_failure"].get<std::string>().find("not finite"), std::string::npos);
}

// Issue "Safe inputs and outputs": scenario text and paths never reach a shell or gnuplot code.
TEST(RunSafety, GnuplotQuotingKeepsEveryByteLiteral) {
  EXPECT_EQ(gnuplot_quoted("a'b"), "'a''b'");
  EXPECT_EQ(gnuplot_quoted("x\ny\r\t"), "'x\\ny\\r\\t'");
  EXPECT_EQ(gnuplot_quoted("`touch p` @macro \\n"), "'`touch p` @macro \\n'");  // inert in ''
  EXPECT_EQ(gnuplot_quoted(std::string("\x1b\x7f", 2)), "'\\x1b\\x7f'");
}

nlohmann::json hostile_high_gain_scenario(const std::string& payload) {
  nlohmann::json j = nlohmann::json::parse(R"({"name": "x", "model": {"name": "oscillator",
    "scheme": "rk4", "step": 0.01}, "x0": [-0.5, 0.0], "initial_guess": [-0.3, 0.0],
    "steps": 400, "settle_time": 1.0, "observers": [{"type": "high_gain", "name": "hg",
    "N": 4, "alpha": "explicit", "inverse": true}, {"type": "ekf"}]})");
  j["name"] = payload;
  j["observers"][0]["name"] = payload;
  return j;
}

// The projection engine is built from the scenario's spec only after the observer's options are
// checked, so a bad option is not hidden behind a bad spec; both are named. An empty name is
// refused where it is read.
TEST(RunErrors, HighGainProjectionSpecAndOptionsAreNamed) {
  const fs::path base = scratch("hg-projection-errors");
  fs::create_directories(base);
  const auto error_with = [&](const std::function<void(nlohmann::json&)>& change) {
    nlohmann::json j = hostile_high_gain_scenario("hg");
    j["observers"][0]["inverse"] = false;
    change(j["observers"][0]);
    const fs::path file = base / "s.json";
    write(file, j.dump());
    return error_of(file.string());
  };
  std::string e = error_with([](nlohmann::json& o) { o["projection"] = "no-such-engine"; });
  EXPECT_NE(e.find("no-such-engine"), std::string::npos) << e;
  e = error_with([](nlohmann::json& o) {
    o["projection"] = "no-such-engine";
    o["jump_threshold"] = 0.0;
  });
  EXPECT_NE(e.find("HighGainOptions::jump_threshold must be > 0"), std::string::npos) << e;
  e = error_with([](nlohmann::json& o) { o["projection"] = "newton"; });  // N = 4 ≠ n = 2
  EXPECT_NE(e.find("'newton' solves square systems only"), std::string::npos) << e;
  e = error_with([](nlohmann::json& o) { o["name"] = ""; });
  EXPECT_NE(e.find("'name' must not be empty"), std::string::npos) << e;
  EXPECT_EQ(error_with([](nlohmann::json& o) { o["projection"] = "ceres:max_iter=50"; }),
            "<no error>");
}

TEST(RunSafety, HostileNamesAndPathsRunNoCommand) {
  const fs::path base = scratch("hostile");
  fs::create_directories(base);
  const fs::path marker = base / "PWNED";
  // A quote and a newline end gnuplot's string and command; system(), backquotes and $( ) would
  // then run; the directory name breaks a shell command line the same way.
  const std::string payload =
      "x'\nsystem(\"touch " + marker.string() + "\")\nprint '`touch " + marker.string() + "`";
  const fs::path file = base / "hostile.json";
  write(file, hostile_high_gain_scenario(payload).dump());
  const fs::path dir =
      base / ("it's `touch " + marker.string() + "` $(touch " + marker.string() + ")\nout");
  for (const std::string sweep : {"", "theta=0.1,0.2"}) {
    std::ostringstream out, err;
    RunOptions o;
    o.out_dir = dir.string();
    o.sweep = sweep;
    ASSERT_NO_THROW(run_scenario(file.string(), o, out, err)) << err.str();
    EXPECT_FALSE(fs::exists(marker)) << "a command ran (sweep '" << sweep << "')";
    if (have_gnuplot()) {
      EXPECT_TRUE(fs::exists(dir / (sweep.empty() ? "states.png" : "sweep.png")))
          << out.str() << err.str();
      EXPECT_EQ(err.str().find("warning: no"), std::string::npos) << err.str();
    }
    // The run's marker; the sweep that follows writes sweep.csv last and removes the run's files.
    EXPECT_EQ(fs::exists(dir / "summary.json"), sweep.empty());
    EXPECT_EQ(fs::exists(dir / "trajectories.csv"), sweep.empty());
  }
  // The payload name (a quote, newlines) is one RFC 4180 field of sweep.csv, read back intact.
  const auto records = csv_records(dir / "sweep.csv");
  ASSERT_EQ(records.size(), 3u);  // header, θ = 0.1 and 0.2 for the one high-gain observer
  for (const auto& record : records) EXPECT_EQ(record.size(), records.front().size());
  EXPECT_EQ(records[1][1], payload);
}

// A value of the wrong type nested 70 000 levels deep (140 KB) crashed the error printer: parsing
// stops at 64 levels naming the file, the key and the limit; values in messages are excerpts.
TEST(RunSafety, DeepOrHugeJsonValuesGiveShortErrors) {
  const fs::path f = scratch("deep.json");
  write(f, "{\"name\": \"deep\", \"model\": " + std::string(70000, '[') + std::string(70000, ']') +
               "}");
  std::string e = error_of(f.string());
  EXPECT_NE(e.find(f.string()), std::string::npos) << e.substr(0, 300);
  EXPECT_NE(e.find("nested deeper than 64 levels (under key 'model')"), std::string::npos)
      << e.substr(0, 300);
  EXPECT_LT(e.size(), 400u);

  nlohmann::json j = to_json(load_scenario("chua-fp"));
  j["observers"][0]["tol"] = std::vector<double>(10000, 1.0);  // the wrong type, and large
  write(f, j.dump());
  e = error_of(f.string());
  EXPECT_NE(e.find("'tol' must be a finite number, got [1.0,1.0,"), std::string::npos) << e;
  EXPECT_LT(e.size(), 300u) << e;
}

TEST(RunSafety, OutOfRangeIntegersNameTheKeyAndTheRange) {
  const fs::path f = scratch("ranges.json");
  const auto error_with = [&](const std::function<void(nlohmann::json&)>& edit) {
    nlohmann::json j = to_json(load_scenario("chua-fp"));
    edit(j);
    write(f, j.dump());
    return error_of(f.string());
  };
  std::string e = error_with([](nlohmann::json& j) { j["observers"][0]["window"] = -3; });
  EXPECT_NE(e.find("'window' = -3 is out of range: must be in 0..100000"), std::string::npos) << e;
  e = error_with([](nlohmann::json& j) { j["steps"] = 9223372036854775808ULL; });  // 2^63
  EXPECT_NE(e.find("'steps' = 9223372036854775808 is out of range"), std::string::npos) << e;
  e = error_with([](nlohmann::json& j) { j["steps"] = 100000000000LL; });
  EXPECT_NE(e.find("must be in 1..10000000"), std::string::npos) << e;
  e = error_with([](nlohmann::json& j) { j["seed"] = -1; });
  EXPECT_NE(e.find("'seed' = -1 is out of range"), std::string::npos) << e;
  EXPECT_NE(
      error_of("chua-fp", {.steps = 100000000000L}).find("'steps' = 100000000000 is out of range"),
      std::string::npos);
}

// Plots are best-effort: a gnuplot that fails costs the PNGs and a warning, not the run's data.
TEST(RunSafety, AFailingGnuplotLeavesTheDataAndAWarning) {
  std::optional<test::FakeProgramOnPath> fake;
  fake.emplace(scratch("fake_gnuplot_bin"), "gnuplot",
               "#!/bin/sh\necho '         plot x' >&2\n"
               "echo '\"'\"$1\"'\" line 7: all points y value undefined!' >&2\nexit 1\n");
  const fs::path dir = scratch("failing_plots");
  std::ostringstream out, err;
  RunOptions o;
  o.steps = 50;
  o.out_dir = dir.string();
  EXPECT_NO_THROW(run_scenario("chua-fp", o, out, err));
  fake.reset();
  EXPECT_TRUE(fs::exists(dir / "summary.json"));
  EXPECT_TRUE(fs::exists(dir / "trajectories.csv"));
  EXPECT_NE(err.str().find("warning: no PNG plots: gnuplot failed (\"plots.gp\" line 7: all "
                           "points y value undefined!"),
            std::string::npos)
      << err.str();
  std::ifstream in(dir / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(in);
  ASSERT_TRUE(summary.contains("warnings"));
  EXPECT_NE(summary["warnings"].dump().find("no PNG plots"), std::string::npos);
}

TEST(Run, WindowLongerThanDataIsAnError) {
  EXPECT_NE(error_of("chua-fp", {.steps = 4}).find("window of 6 samples is longer than the data"),
            std::string::npos);
}

// A model of run-time size by name: the reaction–diffusion chain with 120 cells, its x0 written
// out as a script would, its covariances as one number v for v I; the EKF's sparse covariance
// propagation (through AnyModel: the dense Jacobian's nonzeros) gives the dense one's numbers,
// and both track. A negative v is refused by the key's name.
// 40 samples of T = 0.25 (no measurement noise, the CLI's default).
TEST(Run, AReactionDiffusionChainOfRunTimeSize) {
  const int n = 120;
  nlohmann::json x0 = nlohmann::json::array(), guess = nlohmann::json::array();
  for (int i = 0; i < n; ++i) {
    x0.push_back(1.0 / (1.0 + std::exp((i - 30.0) / 3.0)));
    guess.push_back(1.0 / (1.0 + std::exp((i - 40.0) / 3.0)));
  }
  nlohmann::json ekf = {
      {"type", "ekf"}, {"initial_covariance", 0.25}, {"process_covariance", 1e-6}};
  nlohmann::json dense = ekf;
  dense["sparse_jacobian"] = false;
  const nlohmann::json scenario = {{"name", "chain"},
                                   {"model",
                                    {{"name", "reaction-diffusion"},
                                     {"step", 0.25},
                                     {"parameters", {{"cells", n}, {"sensors", 24}}}}},
                                   {"x0", x0},
                                   {"initial_guess", guess},
                                   {"steps", 40},
                                   {"observers", {ekf, dense}}};
  const fs::path f = scratch("chain.json"), dir = scratch("chain-out");
  nlohmann::json negative = scenario;
  negative["observers"][0]["initial_covariance"] = -0.25;
  write(f, negative.dump());
  EXPECT_NE(error_of(f.string()).find("initial_covariance must be positive semi-definite"),
            std::string::npos)
      << error_of(f.string());
  write(f, scenario.dump());
  std::ostringstream out, err;
  run_scenario(f.string(), {.out_dir = dir.string()}, out, err);
  std::ifstream in(dir / "summary.json");
  const auto summary = nlohmann::json::parse(in);
  const auto& a = summary["observers"][0];
  const auto& b = summary["observers"][1];
  EXPECT_TRUE(a["failures"].empty()) << a.dump();
  ASSERT_TRUE(a["mse"].is_array()) << a.dump();
  ASSERT_EQ(a["mse"].size(), static_cast<std::size_t>(n));
  double worst = 0.0;
  for (std::size_t i = 0; i < a["mse"].size(); ++i) {
    const double mse = a["mse"][i].get<double>();
    EXPECT_NEAR(mse, b["mse"][i].get<double>(), 1e-9 * (1e-6 + mse)) << "state " << i;
    worst = std::max(worst, mse);
  }
  EXPECT_GT(worst, 1e-3);  // the guess starts 10 cells off: errors up to 0.9 in those cells
  // The error reaches 1e-3 within the first half of the run's 10 time units (4.25 when written).
  ASSERT_TRUE(a["time_to_1e-3"].is_number()) << a.dump();
  EXPECT_LT(a["time_to_1e-3"].get<double>(), 5.0);
  EXPECT_EQ(a["time_to_1e-3"], b["time_to_1e-3"]);
  // 12 of the 120 states get a panel (one each asked Cairo for a 36 000-pixel image).
  std::ifstream script(dir / "plots.gp");
  const std::string text((std::istreambuf_iterator<char>(script)),
                         std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("set multiplot layout 12,1 title 'x1, x11, x22,"), std::string::npos) << text;
  EXPECT_NE(text.find("x120 (12 of 120 states; trajectories.csv has all)'"), std::string::npos);
}

TEST(Run, RecordedDataWithMissingSamplesAndNoTruth) {
  // Measurements from a simulation, written as CSV with one sample missing.
  const fs::path sim = scratch("sim");
  std::ostringstream out, err;
  run_scenario("chua-fp", {.steps = 60, .out_dir = sim.string()}, out, err);
  std::ifstream traj(sim / "trajectories.csv");
  std::string line;
  std::getline(traj, line);
  const fs::path data = scratch("data.csv");
  std::ofstream csv(data);
  csv << "t,y1\n";
  for (int k = 0; std::getline(traj, line); ++k) {
    std::stringstream ss(line);
    std::string t, x1;
    std::getline(ss, t, ',');
    std::getline(ss, x1, ',');
    csv << t << ',' << (k == 30 ? "nan" : x1) << '\n';
  }
  csv.close();
  const fs::path outdir = scratch("from-data");
  std::ostringstream out2, err2;
  run_scenario("chua-fp", {.out_dir = outdir.string(), .data_file = data.string()}, out2, err2);
  std::ifstream in(outdir / "summary.json");
  const auto summary = nlohmann::json::parse(in);
  for (const auto& o : summary["observers"]) {
    EXPECT_FALSE(o.contains("mse")) << o.dump();  // no truth: no MSE
  }
  EXPECT_EQ(summary["observers"][0]["failures"]["missing_measurement"], 1);
  // A sweep compares with the truth: recorded data is refused (the run layer's refusal, named
  // with the CLI's flag).
  const std::string no_truth =
      error_of("chua-fp", {.data_file = data.string(), .sweep = "gamma=5,20"});
  EXPECT_NE(no_truth.find("--sweep needs simulated data (the truth)"), std::string::npos)
      << no_truth;

  write(data, "t,y1\n0,1.0\n0.05,abc\n");
  const std::string e = error_of("chua-fp", {.data_file = data.string()});
  EXPECT_NE(e.find(data.string() + ":3: cell 2 'abc' is not a number"), std::string::npos) << e;
  write(data, "0,1.0,2.0\n");
  EXPECT_NE(error_of("chua-fp", {.data_file = data.string()}).find("expected 2 columns"),
            std::string::npos);
}

TEST(Run, LanderScenarioStopsAtTheDomainBoundary) {
  const fs::path f = scratch("lander.json");
  write(f, R"({"name": "lander-ekf",
    "model": {"name": "lander", "step": 0.01},
    "x0": [-700, 0, 1500], "initial_guess": [-690, 1, 1400], "steps": 100000,
    "input": {"kind": "constant", "value": 1},
    "observers": [{"type": "ekf"}]})");
  std::ostringstream out, err;
  run_scenario(f.string(), {}, out, err);
  EXPECT_NE(err.str().find("mass x3"), std::string::npos) << err.str();
  EXPECT_NE(err.str().find("leaves its domain"), std::string::npos) << err.str();
}

// What fails before the run starts leaves nothing behind: a bad scenario creates no --out
// directory; a simulation without a sample still says why it stopped, before the error.
TEST(RunSafety, AFailureBeforeTheRunLeavesNoDirectoryAndSaysWhy) {
  const fs::path out = scratch("never_created") / "out";
  fs::remove_all(out.parent_path());
  EXPECT_NE(error_of("no-such-scenario", {.out_dir = out.string()}).find("no-such-scenario"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(out.parent_path())) << "a bad scenario created " << out;
  const fs::path broken = scratch("broken.json");
  write(broken, R"({"name": "broken", "steps": 0})");
  error_of(broken.string(), {.out_dir = out.string()});
  EXPECT_FALSE(fs::exists(out.parent_path())) << "a bad scenario file created " << out;

  nlohmann::json j = to_json(load_scenario("pi-lander"));
  j["x0"][2] = -1.0;  // no mass: the model leaves its domain at the first sample
  const fs::path lander = scratch("massless.json");
  write(lander, j.dump());
  std::ostringstream out_text, err;
  EXPECT_THROW(run_scenario(lander.string(), {}, out_text, err), std::runtime_error);
  EXPECT_NE(err.str().find("nlobs: simulation stopped at sample 0"), std::string::npos)
      << err.str();
}

// Runs a built-in scenario into a scratch directory and returns summary.json.
nlohmann::json run_summary(const std::string& name, std::string* err_text = nullptr) {
  const fs::path dir = scratch(name);
  std::ostringstream out, err;
  run_scenario(name, {.out_dir = dir.string()}, out, err);
  if (err_text) *err_text = err.str();
  std::ifstream in(dir / "summary.json");
  return nlohmann::json::parse(in);
}

const nlohmann::json& observer_of(const nlohmann::json& summary, const std::string& name) {
  for (const auto& o : summary["observers"]) {
    if (o["name"] == name) return o;
  }
  throw std::runtime_error("no observer " + name);
}

TEST(RunPi, LinearErrorAfterTwoSecondsStaysWithinTheDerivedBound) {
  const nlohmann::json s = run_summary("pi-linear");
  const double observed = observer_of(s, "pi:unknown-input")["max_error_after"][1];
  ASSERT_EQ(s["pi_bounds"].size(), 1u);
  const auto& b = s["pi_bounds"][0];
  const double n = 3 * 3.14159265358979323846;
  EXPECT_DOUBLE_EQ(b["omega_bound"].get<double>(), n);
  // UUB, not zero: Ω = f' = 3π cos(πt) is a sinusoid, so the error settles to exactly
  // N |G(jπ)| = 1.155 — below our L1 bound (1.75) and the paper's δ (18.1).
  const double sinusoid = n * pi_sinusoid_gain({8, 15}, 3.14159265358979323846);
  EXPECT_NEAR(observed, sinusoid, 0.01 * sinusoid);
  EXPECT_LE(observed, b["eta_error_bound"].get<double>());
  EXPECT_LE(observed, b["paper_delta"].get<double>());
  EXPECT_TRUE(observer_of(s, "ekf")["max_error_after"][1].get<double>() < 1.0);
}

TEST(RunPi, ChuaReconstructionErrorsMatchTheirDerivation) {
  const nlohmann::json s = run_summary("pi-chua");
  // The scenario's N must bound |d(x1 + x3)/dt| on the run it describes.
  CubicChua chua;
  const Discretized<CubicChua> model(chua, 0.001, Scheme::kRk4);
  const Measurements data = simulate(model, Eigen::Vector3d(0.2, 0.2, 0.2), {.steps = 50001});
  double omega = 0.0;
  for (Eigen::Index k = 0; k < data.steps(); ++k) {
    const Eigen::Vector3d dx =
        chua.vector_field(Eigen::Vector3d(data.x.col(k)), CubicChua::Input(), 0.0);
    omega = std::max(omega, std::abs(dx[0] + dx[2]));
  }
  const double n = s["pi_bounds"][0]["omega_bound"];
  EXPECT_LE(omega, n);
  EXPECT_GT(omega, 0.85 * n);
  // x̂3 = −b∫y carries the unobservable constant x3(0) − x̂3(0) = 0.2 and nothing else.
  const auto& alt = observer_of(s, "pi:chua-x3")["max_error_after"];
  EXPECT_NEAR(alt[2].get<double>(), 0.2, 1e-6);
  const double eta_bound = s["pi_bounds"][1]["eta_error_bound"];
  EXPECT_LE(alt[0].get<double>(), 0.2 + eta_bound);
  // The paper's x̂1' = η̂₁ + b y: error c − e1 − k_p e2 with c = x̂1(0) − x1(0) + η(0) = 0.2
  // (γ(0) = 0), so |x1 − x̂1| ≤ 0.2 + N ‖(s + k_p)/(s² + k_p s + k_i)‖₁.
  const auto& paper = observer_of(s, "pi:chua")["max_error_after"];
  const double lag_bound = n * pi_l1_gain({25, 150}, 1.0, 25.0);
  EXPECT_LE(paper[0].get<double>(), 0.2 + lag_bound);
  EXPECT_GT(paper[0].get<double>(), alt[0].get<double>());  // the k_p e2 lag costs accuracy

  // The channel itself: |η − η̂| after the transient within eta_error (trajectories.csv has
  // the truth x1, x3 and the bank's signal "eta").
  std::ifstream csv(scratch("pi-chua") / "trajectories.csv");
  std::string line;
  std::getline(csv, line);
  std::vector<std::string> header;
  std::stringstream hs(line);
  for (std::string cell; std::getline(hs, cell, ',');) header.push_back(cell);
  const auto column = [&](const std::string& name) {
    const auto it = std::find(header.begin(), header.end(), name);
    if (it == header.end()) throw std::runtime_error("no column " + name);
    return static_cast<size_t>(it - header.begin());
  };
  const size_t t_col = column("t"), x1 = column("x1"), x3 = column("x3"),
               eta = column("pi:chua.signal.eta");
  double worst = 0.0;
  while (std::getline(csv, line)) {
    std::vector<double> v;
    std::stringstream ls(line);
    for (std::string cell; std::getline(ls, cell, ',');) v.push_back(std::stod(cell));
    if (v[t_col] >= 10.0) worst = std::max(worst, std::abs(v[x1] + v[x3] - v[eta]));
  }
  EXPECT_LE(worst, s["pi_bounds"][0]["eta_error_bound"].get<double>());
  EXPECT_GT(worst, 0.0);
}

TEST(RunPi, LanderTracksFUntilTheMassRunsOut) {
  std::string err;
  const nlohmann::json s = run_summary("pi-lander", &err);
  EXPECT_NE(err.find("mass x3"), std::string::npos) << err;
  EXPECT_NE(s["stop_message"].get<std::string>().find("leaves its domain"), std::string::npos);
  EXPECT_GT(s["steps"].get<long>(), 13000);  // t ≈ 13.05 s
  // Both channels run with complex eigenvalues of K: warned, δ undefined.
  EXPECT_NE(err.find("channel 'x2': K of eq. (7) has complex eigenvalues"), std::string::npos);
  EXPECT_EQ(s["warnings"].size(), 2u);
  EXPECT_TRUE(s["pi_bounds"][1]["paper_delta"].is_null());
  // Bounded error (docs/observers.md): f peaks at e^6 = 403; the bank lags it by up to 150.
  const auto& pi = observer_of(s, "pi:lander");
  EXPECT_LT(pi["max_error_after"][3].get<double>(), 150.0);
  EXPECT_TRUE(pi["failures"].empty());
}

TEST(RunPi, PiScenariosRoundTrip) {
  for (const char* name : {"pi-linear", "pi-chua", "pi-lander"}) {
    const Scenario sc = load_scenario(name);
    const nlohmann::json j = to_json(sc);
    EXPECT_EQ(to_json(parse_scenario(j, "round trip")), j) << name;
  }
}

TEST(RunPi, BadPiBankSpecsNameTheProblem) {
  const fs::path f = scratch("bad_pi.json");
  const auto scenario = [](const std::string& observer) {
    return R"({"name": "x", "model": {"name": "unknown-input"}, "x0": [0, 0],
               "initial_guess": [0, 0], "steps": 10, "observers": [)" +
           observer + "]}";
  };
  write(f, scenario(R"({"type": "pi_bank", "bank": "unknown-input", "gains": [[-8, 15]]})"));
  EXPECT_NE(error_of(f.string()).find("gain k_p = -8"), std::string::npos) << error_of(f.string());
  write(f, scenario(R"({"type": "pi_bank", "bank": "unknown-input", "gains": [[8, 15], [1, 1]]})"));
  EXPECT_NE(error_of(f.string()).find("1 channel(s)"), std::string::npos);
  write(f, scenario(R"({"type": "pi_bank", "bank": "nope", "gains": [[8, 15]]})"));
  EXPECT_NE(error_of(f.string()).find("valid: unknown-input, chua"), std::string::npos);
  write(f, scenario(R"({"type": "pi_bank", "bank": "chua", "gains": [[8, 15]]})"));
  EXPECT_NE(error_of(f.string()).find("estimates 3 states"), std::string::npos);
  write(f, scenario(R"({"type": "pi_bank", "bank": "unknown-input", "gains": [[8, 15]],
                        "omega_bounds": {"g": 1}})"));
  EXPECT_NE(error_of(f.string()).find("'g'"), std::string::npos) << error_of(f.string());
  write(f, scenario(R"({"type": "ekf", "model": {"name": "lorenz"}})"));
  EXPECT_NE(error_of(f.string()).find("sizes and sample time"), std::string::npos);
}

TEST(RunMvt, ChaoticCasesAsDocumented) {
  std::string err;
  const nlohmann::json s = run_summary("mvt-chaotic", &err);
  for (const char* name :
       {"mvt-case1", "mvt-case1-injection", "mvt-case2", "mvt-case2-injection"}) {
    const auto& o = observer_of(s, name);
    EXPECT_LE(o["max_beta_residual"].get<double>(), 1e-8) << name;
    EXPECT_TRUE(o["failures"].empty()) << name;
  }
  // Case 1: below 1e-3 from t = 2.73 s, both variants (the correction sees ν ≡ 0).
  EXPECT_NEAR(observer_of(s, "mvt-case1")["time_to_1e-3"].get<double>(), 2.727, 0.01);
  EXPECT_NEAR(observer_of(s, "mvt-case1-injection")["time_to_1e-3"].get<double>(), 2.727, 0.01);
  // Case 2 as published never gets there; corrected, it does (t = 4.02 s measured).
  EXPECT_TRUE(observer_of(s, "mvt-case2")["time_to_1e-3"].is_null());
  EXPECT_LT(observer_of(s, "mvt-case2-injection")["time_to_1e-3"].get<double>(), 6.0);
  EXPECT_GT(observer_of(s, "mvt-case2")["max_error_after"][2].get<double>(), 0.05);
  EXPECT_LT(observer_of(s, "mvt-case2-injection")["max_error_after"][2].get<double>(), 1e-6);
  EXPECT_FALSE(observer_of(s, "ekf").contains("max_beta_residual"));
  EXPECT_TRUE(observer_of(s, "ekf").contains("time_to_1e-3"));
  // β and ‖X(β)‖ per sample, the paper's Figs. 2 and 3.
  std::ifstream csv(scratch("mvt-chaotic") / "trajectories.csv");
  std::string header;
  std::getline(csv, header);
  for (const char* column : {"mvt-case1.signal.residual", "mvt-case1.signal.beta3",
                             "mvt-case2-injection.signal.ehat3"}) {
    EXPECT_NE(header.find(column), std::string::npos) << column;
  }
}

TEST(RunMvt, RobotScenarioRunsBesideTheEkf) {
  const nlohmann::json s = run_summary("mvt-robot");
  EXPECT_LT(observer_of(s, "mvt")["time_to_1e-3"].get<double>(), 1.0);
  EXPECT_TRUE(observer_of(s, "mvt-other-e0")["time_to_1e-3"].is_null());
  EXPECT_LT(observer_of(s, "mvt-other-e0-injection")["max_error_after"][3].get<double>(), 1e-6);
  EXPECT_LE(observer_of(s, "mvt-other-e0-injection")["max_beta_residual"].get<double>(), 1e-8);
}

TEST(RunMvt, ScenariosRoundTripAndBadSpecsNameTheProblem) {
  for (const char* name : {"mvt-chaotic", "mvt-robot"}) {
    const nlohmann::json j = to_json(load_scenario(name));
    EXPECT_EQ(to_json(parse_scenario(j, "round trip")), j) << name;
  }
  const fs::path f = scratch("bad_mvt.json");
  const auto scenario = [](const std::string& model, const std::string& observer) {
    return R"({"name": "x", "model": {"name": ")" + model +
           R"("}, "x0": [0, 0, 0], "initial_guess": [0, 0, 0], "steps": 10, "observers": [)" +
           observer + "]}";
  };
  write(f, scenario("chaotic", R"({"type": "mvt", "error_guess": [1, 1]})"));
  EXPECT_NE(error_of(f.string()).find("'error_guess' must have 3 entries"), std::string::npos);
  write(f, scenario("chaotic", R"({"type": "mvt", "error_guess": [1, 1, 1], "eta": 0.5})"));
  EXPECT_NE(error_of(f.string()).find("'eta' must be >= 1"), std::string::npos);
  write(f, scenario("chaotic", R"({"type": "mvt", "error_guess": [1, 1, 1], "beta_solver": "x"})"));
  EXPECT_NE(error_of(f.string()).find("per-row, nlopt or ceres"), std::string::npos);
  // The cubic Chua circuit measures x2: not y = [I_m 0] x.
  write(f, scenario("cubic-chua", R"({"type": "mvt", "error_guess": [1, 1, 1]})"));
  EXPECT_NE(error_of(f.string()).find("C = [I_m 0]"), std::string::npos) << error_of(f.string());
}

// [HG-EMB23]'s examples: ‖z − ẑ‖ below 1e-6 within the documented times, x̂ → x.
TEST(RunHighGain, OscillatorAndDuffingReachOneMicro) {
  const nlohmann::json osc = run_summary("hg-oscillator");
  for (const char* name : {"hg-inverse", "hg-projection"}) {
    const auto& o = observer_of(osc, name);
    EXPECT_LT(o["time_to_z_1e-6"].get<double>(), 18.0) << name;  // measured 16.9 s
    EXPECT_LT(o["z_rms_after"].get<double>(), 1e-6) << name;
    EXPECT_LT(o["max_error_after"][0].get<double>(), 1e-6) << name;
    EXPECT_LT(o["max_error_after"][1].get<double>(), 1e-6) << name;
    EXPECT_TRUE(o["failures"].empty()) << name;
  }
  EXPECT_FALSE(observer_of(osc, "ekf").contains("time_to_z_1e-6"));
  // The log-scale error plot of the paper's Fig. 6 and ẑ per sample.
  EXPECT_TRUE(fs::exists(scratch("hg-oscillator") / "z_error.png") ||
              !fs::exists("/usr/bin/gnuplot"));
  std::ifstream csv(scratch("hg-oscillator") / "trajectories.csv");
  std::string header;
  std::getline(csv, header);
  for (const char* column : {"hg-inverse.signal.zhat4", "hg-inverse.signal.z_error",
                             "hg-projection.signal.projection_residual"}) {
    EXPECT_NE(header.find(column), std::string::npos) << column;
  }

  const fs::path dir = scratch("hg-duffing");
  std::ostringstream out, err;
  run_scenario("hg-duffing", {.steps = 12001, .out_dir = dir.string()}, out, err);
  std::ifstream in(dir / "summary.json");
  const nlohmann::json duffing = nlohmann::json::parse(in);
  const auto& hg = observer_of(duffing, "hg-duffing");
  EXPECT_LT(hg["time_to_z_1e-6"].get<double>(), 10.0);  // measured 9.0 s
  EXPECT_GT(hg["max_zhat_norm"].get<double>(), 10.0);   // the peaking of the hard start
  EXPECT_LT(hg["final_z_error"].get<double>(), 1e-6);
}

// The θ sweep: smaller θ, more peaking; under noise, larger steady error (the oscillator at
// h = 0.01, 40 s, σ = 1e-3; measured max ‖ẑ‖ 7.2 / 1.63 / 1.65 and z RMS 0.134 / 0.017 / 0.0076).
TEST(RunHighGain, ThetaSweepShowsPeakingAndNoise) {
  const fs::path dir = scratch("hg-sweep"), file = scratch("hg-sweep.json");
  write(file, R"({"name": "osc-sweep", "model": {"name": "oscillator", "scheme": "rk4",
    "step": 0.01}, "x0": [-0.5, 0.0], "initial_guess": [-0.3, 0.0], "steps": 4001,
    "settle_time": 30.0, "observers": [{"type": "high_gain", "name": "hg", "N": 4,
    "alpha": "explicit", "inverse": true,
    "saturation": {"P_diagonal": [0.594, 0.421, 0.266, 0.153]}}, {"type": "ekf"}]})");
  std::ostringstream out, err;
  RunOptions o;
  o.noise = 1e-3;
  o.out_dir = dir.string();
  o.sweep = "theta=0.1,0.2,0.3";
  run_scenario(file.string(), o, out, err);
  std::ifstream csv(dir / "sweep.csv");
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line.rfind("theta,observer,max_zhat_norm,z_rms_after,x_rms_after", 0), 0u) << line;
  std::map<double, std::pair<double, double>> rows;  // θ → (max ‖ẑ‖, z RMS after)
  while (std::getline(csv, line)) {
    std::stringstream fields(line);
    std::string theta, name, peak, z_rms;
    std::getline(fields, theta, ',');
    std::getline(fields, name, ',');
    std::getline(fields, peak, ',');
    std::getline(fields, z_rms, ',');
    EXPECT_EQ(name, "hg");  // the EKF is not swept
    rows[std::stod(theta)] = {std::stod(peak), std::stod(z_rms)};
  }
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_GT(rows[0.1].first, 2.0 * rows[0.3].first);  // peaking
  EXPECT_GT(rows[0.1].second, rows[0.2].second);      // noise amplification
  EXPECT_GT(rows[0.2].second, rows[0.3].second);
  EXPECT_NE(error_of("hg-oscillator", {.sweep = "theta=0.1,x"}).find("'x' is not a number"),
            std::string::npos);
  EXPECT_NE(error_of("mvt-robot", {.sweep = "theta=0.1"}).find("needs a high_gain observer"),
            std::string::npos);
}

// A Lorenz run with the high-gain observer on the map `map` at order N; its summary.
nlohmann::json high_gain_map_run(const std::string& map, int N, std::string* error = nullptr) {
  // 0.3 s (MSE after 0.2 s); under the sanitizers 0.1 s (MSE after 0.05 s): ADOL-C at N = 9 is
  // slow there, and the comparisons are the same on the shorter run.
  const std::string horizon = test::short_tests() ? R"("steps": 101, "settle_time": 0.05)"
                                                  : R"("steps": 301, "settle_time": 0.2)";
  const fs::path f = scratch("hg_map_" + map + "_" + std::to_string(N) + ".json");
  write(f, R"({"name": "m", "model": {"name": "lorenz", "step": 0.001}, "x0": [1, 1, 20],
               "initial_guess": [2, 3, 25], )" +
               horizon + R"(, "observers": [{"type": "high_gain", "name": "hg",
               "theta": 0.05, "N": )" +
               std::to_string(N) + R"(, "map": ")" + map + R"("}]})");
  if (error != nullptr) {
    *error = error_of(f.string());
    return {};
  }
  const fs::path dir = f.parent_path() / f.stem();
  std::ostringstream out, err;
  run_scenario(f.string(), {.out_dir = dir.string()}, out, err);
  std::ifstream in(dir / "summary.json");
  return observer_of(nlohmann::json::parse(in), "hg");
}

// The maps from the model through the CLI: taylor, adolc and ad (taylor up to N = 8) run the
// same observer on Lorenz to rounding.
TEST(RunHighGain, MapsFromTheModelGiveTheSameRun) {
  const nlohmann::json taylor = high_gain_map_run("taylor", 4),
                       adolc = high_gain_map_run("adolc", 4), ad = high_gain_map_run("ad", 4);
  const double z = adolc["final_z_error"].get<double>();
  EXPECT_GT(z, 0.0);
  EXPECT_NEAR(taylor["final_z_error"].get<double>(), z, 1e-8 * (1.0 + z));
  EXPECT_EQ(ad["final_z_error"], taylor["final_z_error"]);
  EXPECT_EQ(ad["mse"], taylor["mse"]);
  EXPECT_TRUE(taylor["mse"].is_array()) << taylor["mse"];  // measured after settling
  EXPECT_TRUE(taylor["failures"].empty());
}

// Past N = 8, ad takes ADOL-C (the same run as adolc) and taylor is refused.
TEST(RunHighGain, PastTheTaylorMapsAdIsAdolc) {
  const nlohmann::json ad9 = high_gain_map_run("ad", 9), adolc9 = high_gain_map_run("adolc", 9);
  EXPECT_EQ(ad9["mse"], adolc9["mse"]);
  EXPECT_TRUE(ad9["mse"].is_array()) << ad9["mse"];
  std::string error;
  high_gain_map_run("taylor", 9, &error);
  EXPECT_NE(error.find("taylor exists for N <= 8"), std::string::npos) << error;
}

TEST(RunHighGain, ScenariosRoundTripAndBadSpecsNameTheProblem) {
  for (const char* name : {"hg-duffing", "hg-oscillator", "hg-lorenz", "hg-vdp"}) {
    const nlohmann::json j = to_json(load_scenario(name));
    EXPECT_EQ(to_json(parse_scenario(j, "round trip")), j) << name;
  }
  const fs::path f = scratch("bad_hg.json");
  const auto scenario = [](const std::string& model, int n, const std::string& observer) {
    const std::string zeros = n == 2 ? "[0, 0]" : n == 3 ? "[0, 0, 0]" : "[0, 0, 0, 0]";
    return R"({"name": "x", "model": {"name": ")" + model + R"("}, "x0": )" + zeros +
           R"(, "initial_guess": )" + zeros + R"(, "steps": 10, "observers": [)" + observer + "]}";
  };
  write(f, scenario("duffing", 2, R"({"type": "high_gain", "theta": 0})"));
  EXPECT_NE(error_of(f.string()).find("'theta' must be > 0"), std::string::npos);
  write(f, scenario("duffing", 2, R"({"type": "high_gain", "poles": [-1, -1, -1, -1, -1, 1]})"));
  EXPECT_NE(error_of(f.string()).find("poles"), std::string::npos) << error_of(f.string());
  write(f,
        scenario("duffing", 2,
                 R"({"type": "high_gain", "saturation": {"P_diagonal": [1, 1], "box": [1, 1]}})"));
  EXPECT_NE(error_of(f.string()).find("give one of"), std::string::npos);
  write(f, scenario("duffing", 2,
                    R"({"type": "high_gain", "saturation": {"P": [[1, 0], [0, 1]],
                        "P_diagonal": [1, 1]}})"));
  EXPECT_NE(error_of(f.string()).find("give one of"), std::string::npos);
  write(f, scenario("pendulum", 2, R"({"type": "high_gain", "N": 3})"));
  EXPECT_NE(error_of(f.string()).find("depends on t"), std::string::npos) << error_of(f.string());
  write(f, scenario("lorenz", 3, R"({"type": "high_gain", "map": "explicit"})"));
  EXPECT_NE(error_of(f.string()).find("needs a map built from the model"), std::string::npos)
      << error_of(f.string());
  write(f, scenario("duffing", 2,
                    R"({"type": "high_gain", "saturation": {"P_diagonal": [1, 1, 1, 1, 1, -1]}})"));
  EXPECT_NE(error_of(f.string()).find("not positive definite"), std::string::npos)
      << error_of(f.string());
  write(f, scenario("robot", 4, R"({"type": "high_gain", "N": 4})"));
  EXPECT_NE(error_of(f.string()).find("autonomous model with one output"), std::string::npos)
      << error_of(f.string());
  write(f, scenario("cubic-chua", 3, R"({"type": "high_gain", "N": 4, "map": "explicit"})"));
  EXPECT_NE(error_of(f.string()).find("hand-expanded"), std::string::npos) << error_of(f.string());
  write(f, scenario("cubic-chua", 3, R"({"type": "high_gain"})"));
  EXPECT_NE(error_of(f.string()).find("give 'N'"), std::string::npos) << error_of(f.string());
  write(f, scenario("lorenz", 3, R"({"type": "high_gain", "N": 2})"));
  EXPECT_NE(error_of(f.string()).find("N = 2"), std::string::npos) << error_of(f.string());
  write(f, scenario("lorenz", 3, R"({"type": "high_gain", "map": "tape"})"));
  EXPECT_NE(error_of(f.string()).find("'map' must be ad, taylor, adolc or explicit"),
            std::string::npos)
      << error_of(f.string());
  write(f, scenario("lorenz", 3, R"({"type": "high_gain", "N": 4, "alpha": "explicit"})"));
  EXPECT_NE(error_of(f.string()).find("needs a hand α"), std::string::npos) << error_of(f.string());
}

// [MF-LTV]'s examples through the CLI: noise-free, exact to 1e-6 one horizon after start; under
// noise the derivative estimate far better than finite differences; the sampled-data observer
// converges; Theorem 1's bound holds on the disturbed pendulum.
TEST(RunModulating, ExactNoiseFreeAndBetterThanDifferencesUnderNoise) {
  const fs::path dir = scratch("mf-lti-clean");
  std::ostringstream out, err;
  run_scenario("mf-lti", {.steps = 801, .noise = 0.0, .out_dir = dir.string()}, out, err);
  std::ifstream in(dir / "summary.json");
  const nlohmann::json clean = nlohmann::json::parse(in);
  EXPECT_LT(observer_of(clean, "mf")["max_eta_rel_error_after_horizon"].get<double>(), 1e-6);
  EXPECT_LT(observer_of(clean, "mf-sampled")["final_eta_rel_error"].get<double>(), 1e-3);
  EXPECT_FALSE(observer_of(clean, "finite-difference").contains("final_eta_rel_error"));
  EXPECT_EQ(fs::exists(dir / "eta_error.png"), have_gnuplot());

  const nlohmann::json noisy = run_summary("mf-lti");  // σ = 0.01
  const double mf = observer_of(noisy, "mf")["mse_after_window"][1].get<double>();
  const double fd = observer_of(noisy, "finite-difference")["mse_after_window"][1].get<double>();
  EXPECT_LT(25.0 * mf, fd) << "RMS ratio " << std::sqrt(fd / mf);  // RMS 5× lower

  const fs::path pdir = scratch("mf-pendulum");
  std::ostringstream pout, perr;
  run_scenario("mf-pendulum", {.steps = 801, .out_dir = pdir.string()}, pout, perr);
  std::ifstream pin(pdir / "summary.json");
  const nlohmann::json pendulum = nlohmann::json::parse(pin);
  const auto& p = observer_of(pendulum, "mf");
  EXPECT_GT(p["max_eta_rel_error_after_horizon"].get<double>(), 1e-3);  // the disturbance shows
  // Theorem 1's bound holds and is not vacuous (measured 1.09× the error).
  EXPECT_LE(p["max_eta_error_after_horizon"].get<double>(), p["max_eta_bound"].get<double>());
  EXPECT_GT(p["max_eta_error_after_horizon"].get<double>(), p["max_eta_bound"].get<double>() / 2);
}

// Error vs horizon (noise: shorter is worse) and the sampling-period sweep (converges at 0.5 s,
// not at 2 s with T = 1 s; the measured limit is 1.6 s).
TEST(RunModulating, SweepsOverHorizonSamplingPeriodAndDisturbance) {
  const fs::path dir = scratch("mf-sweep");
  std::ostringstream out, err;
  RunOptions o;
  o.steps = 801;
  o.out_dir = dir.string();
  o.sweep = "horizon=0.2,1";
  run_scenario("mf-lti", o, out, err);
  const auto rows = [&](const std::string& key) {
    std::ifstream csv(dir / "sweep.csv");
    std::string line;
    std::getline(csv, line);
    EXPECT_EQ(line.rfind(key + ",observer,x_rms_after,x2_rms_after", 0), 0u) << line;
    std::map<std::pair<double, std::string>, std::vector<std::string>> table;
    while (std::getline(csv, line)) {
      std::stringstream fields(line);
      std::vector<std::string> cells;
      for (std::string cell; std::getline(fields, cell, ',');) cells.push_back(cell);
      table[{std::stod(cells[0]), cells[1]}] = cells;
    }
    return table;
  };
  auto t = rows("horizon");
  EXPECT_GT(std::stod(t[{0.2, "mf"}][3]), 3.0 * std::stod(t[{1.0, "mf"}][3]));
  EXPECT_GT(std::stod(t[{1.0, "finite-difference"}][3]), 5.0 * std::stod(t[{1.0, "mf"}][3]));

  o.noise = 0.0;
  o.steps = 3001;
  o.sweep = "sample_period=0.5,2";
  run_scenario("mf-lti", o, out, err);
  t = rows("sample_period");
  const std::pair<double, std::string> fast{0.5, "mf-sampled"}, slow{2.0, "mf-sampled"};
  EXPECT_EQ(t[fast][8], "yes");
  EXPECT_EQ(t[slow][8], "no");

  o.steps = 801;
  o.sweep = "a_max=0,1";
  run_scenario("mf-pendulum", o, out, err);
  t = rows("a_max");
  EXPECT_LT(std::stod(t[{0.0, "mf"}][5]), 1e-6);
  const double error = std::stod(t[{1.0, "mf"}][11]), bound = std::stod(t[{1.0, "mf"}][7]);
  EXPECT_LE(error, bound);
  EXPECT_GT(error, bound / 2);

  EXPECT_NE(error_of("hg-oscillator", {.sweep = "horizon=1"}).find("needs a modulating"),
            std::string::npos);
  EXPECT_NE(error_of("mf-lti", {.sweep = "horizon=0"}).find("'0' is not a number > 0"),
            std::string::npos);
  const std::string unknown = error_of("mf-pendulum", {.sweep = "no_such=1"});
  EXPECT_NE(unknown.find("--sweep no_such = 1"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("horizon, sample_period"), std::string::npos) << unknown;
  EXPECT_NE(error_of("mf-lti", {.sweep = "horizon=0.05"}).find("--sweep horizon = 0.05"),
            std::string::npos);  // T/δ = 5: odd for Simpson, named with the value
}

TEST(RunModulating, ScenariosRoundTripAndBadSpecsNameTheProblem) {
  for (const char* name : {"mf-lti", "mf-pendulum"}) {
    const nlohmann::json j = to_json(load_scenario(name));
    EXPECT_EQ(to_json(parse_scenario(j, "round trip")), j) << name;
  }
  const fs::path f = scratch("bad_mf.json");
  const auto scenario = [](const std::string& model, const std::string& observer) {
    return R"({"name": "x", "model": {"name": ")" + model +
           R"(", "step": 0.01}, "x0": [1, 0], "initial_guess": [0, 0], "steps": 10,
           "observers": [)" +
           observer + "]}";
  };
  write(f, scenario("lti-injection", R"({"type": "modulating", "horizon": 0.03})"));
  EXPECT_NE(error_of(f.string()).find("at least 4"), std::string::npos) << error_of(f.string());
  write(f, scenario("lti-injection", R"({"type": "modulating", "order": 1})"));
  EXPECT_NE(error_of(f.string()).find("order 1 is below n = 2"), std::string::npos);
  write(f, scenario("lti-injection", R"({"type": "modulating", "quadrature": "gauss"})"));
  EXPECT_NE(error_of(f.string()).find("'quadrature'"), std::string::npos);
  write(f, scenario("lti-injection", R"({"type": "modulating", "disturbance_bound": true})"));
  EXPECT_NE(error_of(f.string()).find("no unknown disturbance"), std::string::npos);
  write(f, scenario("duffing", R"({"type": "modulating"})"));
  EXPECT_NE(error_of(f.string()).find("no canonical form"), std::string::npos);
  write(f, scenario("lti-injection", R"({"type": "modulating", "window": 3})"));
  EXPECT_NE(error_of(f.string()).find("window"), std::string::npos);
}

// Recorded data with irregular times, a dropped stretch and cells left empty, on a model with
// two outputs: the EKF, UKF and MHE integrate over each actual interval and update with the
// outputs a row has, and end near the truth (simulated here by the model's own flow); the
// Luenberger observer refuses the rows off its grid, by name, and says so in summary.json.
TEST(RunData, IrregularTimesAndPartlyMissingOutputsRun) {
  const Discretized<ChaoticNoLinear> model(ChaoticNoLinear{}, 0.01, Scheme::kRk4);
  const fs::path data = scratch("irregular.csv");
  Eigen::Vector3d x(1.0, 0.5, 0.2);
  double t = 0.0;
  std::vector<double> times;
  std::vector<Eigen::Vector3d> truth;
  {
    std::ofstream csv(data);
    csv << "t,y1,y2\n" << std::setprecision(17);
    for (int k = 0; k < 400; ++k) {
      const Eigen::Vector2d y = model.h(x);
      times.push_back(t);
      truth.push_back(x);
      csv << t << ',';
      if (k % 4 != 1) csv << y[0];  // empty cells: outputs not measured in that row
      csv << ',';
      if (k % 5 != 2) csv << y[1];
      csv << '\n';
      // On and off the grid, with a gap of 0.05 s once.
      const double dt = k == 200 ? 0.05 : 0.01 * (1.0 + 0.5 * std::sin(1.3 * k));
      x = model.flow(x, Discretized<ChaoticNoLinear>::Input(), t, dt);
      t += dt;
    }
  }
  const fs::path f = scratch("irregular.json");
  write(f, R"({"name": "irregular", "model": {"name": "chaotic", "step": 0.01},
    "x0": [1.0, 0.5, 0.2], "initial_guess": [1.2, 0.4, 0.0], "steps": 400, "observers": [
    {"type": "ekf", "process_covariance": [[1e-8, 0, 0], [0, 1e-8, 0], [0, 0, 1e-8]]},
    {"type": "ukf", "process_covariance": [[1e-8, 0, 0], [0, 1e-8, 0], [0, 0, 1e-8]]},
    {"type": "mhe", "horizon": 8, "process_covariance": [[1e-8, 0, 0], [0, 1e-8, 0], [0, 0, 1e-8]]},
    {"type": "luenberger", "gain": [[0.5, 0], [0, 0.5], [0, 0]]}]})");
  const fs::path dir = scratch("irregular-out");
  std::ostringstream out, err;
  run_scenario(f.string(), {.out_dir = dir.string(), .data_file = data.string()}, out, err);
  std::ifstream in(dir / "summary.json");
  const auto summary = nlohmann::json::parse(in);
  const auto records = csv_records(dir / "trajectories.csv");
  ASSERT_EQ(records.size(), 401u);
  const std::vector<std::string>& header = records[0];
  for (const auto& o : summary["observers"]) {
    const std::string name = o["name"];
    if (name == "luenberger") {
      EXPECT_GT(o["failures"].value("non_uniform", 0), 100) << o.dump();
      EXPECT_NE(o.value("first_failure", "").find("constant gain"), std::string::npos) << o.dump();
      continue;
    }
    EXPECT_FALSE(o["failures"].contains("non_uniform")) << o.dump();
    EXPECT_FALSE(o["failures"].contains("non_finite_estimate")) << o.dump();
    const auto column = std::find(header.begin(), header.end(), name + ".x1") - header.begin();
    ASSERT_LT(column + 2, static_cast<long>(header.size())) << name;
    for (int k : {300, 399}) {
      const auto& row = records[static_cast<std::size_t>(k) + 1];
      EXPECT_NEAR(std::stod(row[0]), times[static_cast<std::size_t>(k)],
                  1e-9);  // written with 12 digits
      for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(std::stod(row[static_cast<std::size_t>(column + i)]),
                    truth[static_cast<std::size_t>(k)][i], 2e-3)
            << name << " x" << i + 1 << " at k = " << k;
      }
    }
  }
}

// --allow-late: a row that comes after later rows (a slow sensor). The MHE takes it into its
// horizon and gives the estimates of the same rows in order; the EKF refuses it by name; without
// the flag the file is an error that names the row and the flag.
TEST(RunData, LateRowsReachTheMheWithAllowLate) {
  const Discretized<BatchReactor> model(BatchReactor{}, 0.25, Scheme::kRk4);
  Eigen::Vector3d x(0.5, 0.05, 0.0);
  std::vector<std::string> rows;
  for (int k = 0; k < 50; ++k) {
    std::ostringstream row;
    row << std::setprecision(17) << 0.25 * k << ','
        << model.h(x)[0] + 0.25 * std::sin(7.0 * k);  // a deterministic "noise"
    rows.push_back(row.str());
    x = model.f(x, Discretized<BatchReactor>::Input(), k);
  }
  const fs::path in_order = scratch("in-order.csv"), late = scratch("late.csv");
  {
    std::ofstream a(in_order), b(late);
    a << "t,y1\n";
    b << "t,y1\n";
    for (int k = 0; k < 50; ++k) {
      a << rows[static_cast<std::size_t>(k)] << '\n';
      if (k == 30) continue;
      b << rows[static_cast<std::size_t>(k)] << '\n';
      if (k == 32) b << rows[30] << '\n';  // row 30 arrives after row 32
    }
  }
  const fs::path f = scratch("late.json");
  write(f, R"({"name": "late", "model": {"name": "batch-reactor"}, "x0": [0.5, 0.05, 0],
    "initial_guess": [1, 0, 4], "steps": 50, "observers": [
    {"type": "ekf", "initial_covariance": [[0.25, 0, 0], [0, 0.25, 0], [0, 0, 0.25]],
     "process_covariance": [[1e-6, 0, 0], [0, 1e-6, 0], [0, 0, 1e-6]],
     "measurement_covariance": [[0.0625]]},
    {"type": "mhe", "horizon": 10, "lower_bounds": [0, 0, 0],
     "initial_covariance": [[0.25, 0, 0], [0, 0.25, 0], [0, 0, 0.25]],
     "process_covariance": [[1e-6, 0, 0], [0, 1e-6, 0], [0, 0, 1e-6]],
     "measurement_covariance": [[0.0625]]}]})");
  EXPECT_NE(error_of(f.string(), {.data_file = late.string()}).find("--allow-late"),
            std::string::npos);
  const fs::path dir_a = scratch("in-order-out"), dir_b = scratch("late-out");
  std::ostringstream out, err;
  run_scenario(f.string(), {.out_dir = dir_a.string(), .data_file = in_order.string()}, out, err);
  run_scenario(f.string(),
               {.out_dir = dir_b.string(), .data_file = late.string(), .allow_late = true}, out,
               err);
  std::ifstream in(dir_b / "summary.json");
  const auto summary = nlohmann::json::parse(in);
  EXPECT_EQ(summary["observers"][0]["failures"].value("non_uniform", 0), 1)
      << summary["observers"][0].dump();
  EXPECT_NE(summary["observers"][0].value("first_failure", "").find("does not come after"),
            std::string::npos);
  EXPECT_TRUE(summary["observers"][1]["failures"].empty()) << summary["observers"][1].dump();
  const auto a = csv_records(dir_a / "trajectories.csv"),
             b = csv_records(dir_b / "trajectories.csv");
  ASSERT_EQ(a.size(), b.size());
  const auto column = std::find(a[0].begin(), a[0].end(), "mhe.x1") - a[0].begin();
  ASSERT_LT(column + 2, static_cast<long>(a[0].size()));
  // File row 33 of the late run is sample 30, the last one taken with every row up to 32: from
  // there the MHE's estimates are those in order while sample 30 is in the horizon (N = 10).
  for (std::size_t row = 33; row <= 40; ++row) {
    for (int i = 0; i < 3; ++i) {
      const std::size_t c = static_cast<std::size_t>(column + i);
      EXPECT_NEAR(std::stod(b[row][c]), std::stod(a[row][c]), 1e-7) << "row " << row;
    }
  }
}

// Recorded data with one sample off the grid: refused (named, state kept) or resampled.
TEST(RunModulating, NonUniformFileIsRefusedOrResampled) {
  const fs::path data = scratch("mf-nonuniform.csv");
  {
    std::ofstream out(data);
    out << "t,y\n";
    for (int k = 0; k < 300; ++k) {
      const double t = 0.01 * k + (k == 150 ? 0.004 : 0.0);
      out << t << ',' << 2.0 * std::cos(t) << '\n';
    }
  }
  const fs::path f = scratch("mf-file.json");
  const auto write_scenario = [&](bool resample) {
    write(f, std::string(R"({"name": "mf-file", "model": {"name": "lti-injection", "step": 0.01},
      "x0": [2, 0], "initial_guess": [0, 0], "steps": 300, "observers": [{"type": "modulating",
      "resample": )") +
                 (resample ? "true" : "false") + "}]}");
  };
  write_scenario(false);
  const fs::path dir = scratch("mf-file-out");
  std::ostringstream out, err;
  run_scenario(f.string(), {.out_dir = dir.string(), .data_file = data.string()}, out, err);
  EXPECT_NE(out.str().find("off the uniform grid"), std::string::npos) << out.str();
  write_scenario(true);
  std::ostringstream out2, err2;
  run_scenario(f.string(), {.out_dir = dir.string(), .data_file = data.string()}, out2, err2);
  EXPECT_EQ(out2.str().find("off the uniform grid"), std::string::npos) << out2.str();
}

// --data with a time jump (200 rows, then 200 from t = 1e9): a sample's work must not grow with
// the gap (it stepped through all 1e11 skipped grid times). Times so large that their rounding
// spans the grid step (1e16, 1e17 at δ = 0.01) are refused, not looped on.
TEST(RunModulating, ATimeJumpCostsNothingAndRestartsTheWindow) {
  for (const bool resample : {false, true}) {
    const fs::path data = scratch("mf-jump.csv");
    {
      std::ofstream out(data);
      out << std::setprecision(17) << "t,y\n";
      for (int k = 0; k < 200; ++k) out << 0.01 * k << ',' << 2.0 * std::cos(0.01 * k) << '\n';
      for (int k = 0; k < 200; ++k) {
        const double t = 1e9 + 0.01 * k;
        out << t << ',' << 2.0 * std::cos(t) << '\n';
      }
      out << 1e16 << ',' << 1.0 << '\n' << 1e17 << ',' << 1.0 << '\n';
    }
    const fs::path f = scratch("mf-jump.json");
    write(f, std::string(R"({"name": "mf-jump", "model": {"name": "lti-injection", "step": 0.01},
      "x0": [2, 0], "initial_guess": [0, 0], "steps": 300, "observers": [{"type": "modulating",
      "resample": )") +
                 (resample ? "true" : "false") + "}]}");
    std::ostringstream out, err;
    run_scenario(f.string(), {.data_file = data.string()}, out, err);
    EXPECT_NE(out.str().find("missing_measurement"), std::string::npos) << out.str();
    EXPECT_NE(out.str().find("non_uniform"), std::string::npos) << out.str();  // 1e17: refused
  }
}

}  // namespace
}  // namespace nlobs::cli
