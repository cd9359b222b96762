// `nlobs run`: the chua-fp experiment's claims, the output contract, scenario files and
// recorded data, and every bad input the issue lists.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "run_command.hpp"
#include "scenario.hpp"

namespace nlobs::cli {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path p =
      fs::temp_directory_path() / ("nlobs_test_run_" + std::to_string(::getpid())) / name;
  fs::create_directories(p.parent_path());
  return p;
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
  std::ofstream(p) << text;
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
  for (const auto& entry : fs::directory_iterator(dir)) {
    EXPECT_NE(entry.path().extension(), ".tmp") << entry.path();  // nothing half-written
  }
  std::ifstream csv(dir / "trajectories.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header.rfind("t,x1,x2,x3,window:picard.x1", 0), 0U) << header;
}

TEST(Run, ScenarioJsonRoundTrip) {
  const Scenario s = load_scenario("chua-fp");
  const nlohmann::json j = to_json(s);
  const Scenario back = parse_scenario(j, "round trip");
  EXPECT_EQ(to_json(back), j);
  EXPECT_EQ(back.observers.size(), s.observers.size());
  EXPECT_EQ(back.observers[5].window, 6);
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
  EXPECT_NE(error_of(f.string()).find("unknown option(s) m"), std::string::npos);

  write(f, "{ not json");
  EXPECT_NE(error_of(f.string()).find("not valid JSON"), std::string::npos);
  EXPECT_NE(error_of("no-such-scenario").find("neither a built-in scenario"), std::string::npos);
}

TEST(Run, WindowLongerThanDataIsAnError) {
  EXPECT_NE(error_of("chua-fp", {.steps = 4}).find("window of 6 samples is longer than the data"),
            std::string::npos);
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

  write(data, "t,y1\n0,1.0\n0.05,abc\n");
  const std::string e = error_of("chua-fp", {.data_file = data.string()});
  EXPECT_NE(e.find(data.string() + ":3: malformed row"), std::string::npos) << e;
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

}  // namespace
}  // namespace nlobs::cli
