// Behaviour guard for refactorings: every built-in scenario (and a few noisy runs) is run by the
// nlobs executable and its summary.json is compared, number by number, with the one recorded in
// tests/data/scenario_summaries.json before the refactoring. Only the wall-clock field
// ns_per_step is left out. A built-in scenario without a recorded summary fails the test.
//
// When a change is meant to change results, record them again and review the diff:
//   NLOBS_UPDATE_BASELINE=1 ctest --test-dir build -R ScenarioBaseline
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "cli_test_files.hpp"

namespace {

// Runs the CLI with PATH emptied (no gnuplot: the same summary on every machine).
int run_cli(const std::string& args, std::string& out) {
  const std::string cmd = "PATH=/nonexistent " + std::string(NLOBS_CLI_PATH) + " " + args + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (pipe == nullptr) return -1;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, pipe)) > 0) out.append(buf, n);
  const int rc = pclose(pipe);
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

std::vector<std::string> builtin_scenarios() {
  std::string out;
  EXPECT_EQ(run_cli("list scenarios", out), 0) << out;
  std::istringstream in(out);
  std::string line;
  std::vector<std::string> names;
  std::getline(in, line);  // the heading
  while (std::getline(in, line)) {
    const auto first = line.find_first_not_of(' ');
    if (first != std::string::npos) names.push_back(line.substr(first));
  }
  return names;
}

// The runs recorded: each built-in scenario as shipped, and noisy runs of the families whose
// noise handling differs.
std::vector<std::string> cases() {
  std::vector<std::string> out = builtin_scenarios();
  out.push_back("chua-fp --noise 0.01 --seed 7");
  out.push_back("hg-duffing --noise 0.001 --seed 3");
  out.push_back("mvt-chaotic --noise 0.001 --seed 5 --steps 2000");
  out.push_back("pi-lander --noise 0.01 --seed 2");
  out.push_back("mf-lti --noise 0.001 --seed 4");
  return out;
}

nlohmann::json without_timing(nlohmann::json j) {
  if (j.is_object()) {
    j.erase("ns_per_step");
    for (auto& [key, value] : j.items()) value = without_timing(value);
  } else if (j.is_array()) {
    for (auto& value : j) value = without_timing(value);
  }
  return j;
}

// Numbers agree to a relative 1e-9 (bit-identical in one build; the margin absorbs a different
// optimisation level, as under the sanitizers); everything else exactly.
void expect_same(const nlohmann::json& want, const nlohmann::json& got, const std::string& where) {
  if (want.is_number() && got.is_number()) {
    const double a = want.get<double>(), b = got.get<double>();
    const bool same = a == b || (std::isnan(a) && std::isnan(b)) ||
                      std::abs(a - b) <= 1e-9 * std::max(std::abs(a), std::abs(b));
    EXPECT_TRUE(same) << where << ": recorded " << want.dump() << ", now " << got.dump();
    return;
  }
  ASSERT_EQ(want.type_name(), std::string(got.type_name())) << where;
  if (want.is_object()) {
    for (const auto& [key, value] : want.items()) {
      if (!got.contains(key)) {
        ADD_FAILURE() << where << "." << key << " recorded but missing now";
        continue;
      }
      expect_same(value, got[key], where + "." + key);
    }
    for (const auto& [key, value] : got.items()) {
      EXPECT_TRUE(want.contains(key)) << where << "." << key << " is new: " << value.dump();
    }
  } else if (want.is_array()) {
    ASSERT_EQ(want.size(), got.size())
        << where << ": recorded " << want.dump() << ", now " << got.dump();
    for (size_t i = 0; i < want.size(); ++i) {
      expect_same(want[i], got[i], where + "[" + std::to_string(i) + "]");
    }
  } else {
    EXPECT_EQ(want, got) << where;
  }
}

nlohmann::json run_case(const std::string& args, size_t index) {
  const auto dir = nlobs::test::scratch_path("nlobs_baseline", "run" + std::to_string(index));
  std::string out;
  const int status = run_cli("run " + args + " --out " + dir.string(), out);
  EXPECT_EQ(status, 0) << args << ": " << out;
  std::ifstream in(dir / "summary.json");
  EXPECT_TRUE(in) << args << ": no summary.json";
  if (!in) return nullptr;
  return without_timing(nlohmann::json::parse(in));
}

TEST(ScenarioBaseline, SummariesMatchTheRecordedOnes) {
  const std::vector<std::string> runs = cases();
  ASSERT_GE(runs.size(), 12U);
  const bool update = std::getenv("NLOBS_UPDATE_BASELINE") != nullptr;
  nlohmann::json recorded;
  if (!update) {
    std::ifstream in(NLOBS_BASELINE_PATH);
    ASSERT_TRUE(in) << "cannot read " << NLOBS_BASELINE_PATH;
    recorded = nlohmann::json::parse(in);
  }
  nlohmann::json now = nlohmann::json::object();
  for (size_t i = 0; i < runs.size(); ++i) {
    const std::string& args = runs[i];
    now[args] = run_case(args, i);
    if (update) continue;
    if (!recorded.contains(args)) {
      ADD_FAILURE() << "'" << args << "' has no recorded summary: NLOBS_UPDATE_BASELINE=1 "
                    << "records it (tests/data/scenario_summaries.json)";
      continue;
    }
    expect_same(recorded[args], now[args], args);
  }
  if (update) {
    std::ofstream(NLOBS_BASELINE_PATH) << now.dump(1) << '\n';
    GTEST_SKIP() << "recorded " << runs.size() << " summaries in " << NLOBS_BASELINE_PATH;
  }
}

}  // namespace
