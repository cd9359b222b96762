// Runs the nlobs executable and checks the contract of `nlobs solve chua-window --json`.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

namespace {

struct CliRun {
  int status = -1;
  std::string out;
};

CliRun run(const std::string& args) {
  CliRun r;
  const std::string cmd = std::string(NLOBS_CLI_PATH) + " " + args + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buf{};
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) r.out.append(buf.data(), n);
  const int rc = pclose(pipe);
  r.status = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  return r;
}

TEST(Cli, SolveChuaWindowJsonContract) {
  const CliRun r = run("solve chua-window --tol 1e-10 --json");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto rows = nlohmann::json::parse(r.out);
  ASSERT_TRUE(rows.is_array());
  std::vector<std::string> names;
  for (const auto& row : rows) {
    for (const char* key :
         {"engine", "status", "iterations", "evaluations", "solution", "error", "ns_per_solve"}) {
      ASSERT_TRUE(row.contains(key)) << key << " missing in " << row.dump();
    }
    names.push_back(row["engine"]);
    EXPECT_EQ(row["status"], "converged") << row.dump();
    EXPECT_EQ(row["solution"].size(), 3U);
    EXPECT_LT(row["error"].get<double>(), 1e-6) << row.dump();
    EXPECT_GT(row["ns_per_solve"].get<double>(), 0.0);
  }
  const std::vector<std::string> expected = {"picard",        "aitken",       "steffensen",
                                             "anderson",      "newton",       "kinsol:fp",
                                             "kinsol:fp-aa2", "kinsol:newton"};
  EXPECT_EQ(names, expected);
}

TEST(Cli, EngineSubsetAndTable) {
  const CliRun r = run("solve chua-window --engines steffensen,newton --tol 1e-5");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("steffensen"), std::string::npos);
  EXPECT_NE(r.out.find("kinsol:newton"), std::string::npos);  // KINSOL in the same run
  EXPECT_EQ(r.out.find("picard"), std::string::npos);
}

TEST(Cli, UnknownEngineListsValidOnes) {
  const CliRun r = run("solve chua-window --engines bogus");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("unknown engine 'bogus'"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("steffensen"), std::string::npos) << r.out;
}

TEST(Cli, InvalidToleranceIsAnError) {
  const CliRun r = run("solve chua-window --tol -1");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("--tol"), std::string::npos) << r.out;
}

// Out-of-range integers are errors naming the option and the range, before anything runs
// (--seed -1 became 2^64 - 1, huge --steps ended in std::bad_alloc).
TEST(Cli, OutOfRangeIntegersAreErrors) {
  for (const char* args : {"run chua-fp --seed -1", "run chua-fp --seed 1180591620717411303424",
                           "run chua-fp --steps 0", "run chua-fp --steps 100000000000"}) {
    const CliRun r = run(args);
    EXPECT_NE(r.status, 0) << args;
    EXPECT_TRUE(r.out.find("--seed") != std::string::npos ||
                r.out.find("--steps") != std::string::npos)
        << args << ": " << r.out;
  }
  const CliRun m = run("solve chua-window --engines anderson:m=1000000000 --no-reference");
  EXPECT_NE(m.status, 0);
  EXPECT_NE(m.out.find("'m=1000000000' is out of range: must be in 0.."), std::string::npos)
      << m.out;
}

TEST(Cli, SolveAcceptsEngineSpecs) {
  const CliRun r =
      run("solve chua-window --tol 1e-8 --no-reference --json "
          "--engines anderson:m=2,damping=0.5,ceres,nlopt:LD_SLSQP");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto rows = nlohmann::json::parse(r.out);
  ASSERT_EQ(rows.size(), 3U) << r.out;
  EXPECT_EQ(rows[0]["engine"], "anderson:m=2,damping=0.5");
  EXPECT_EQ(rows[1]["engine"], "ceres");
  EXPECT_EQ(rows[2]["engine"], "nlopt:LD_SLSQP");
  EXPECT_EQ(rows[1]["status"], "converged");
}

TEST(Cli, SuiteMghJsonContract) {
  const CliRun r = run("suite mgh --solvers ceres,minpack:hybrj --json");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto rows = nlohmann::json::parse(r.out);
  ASSERT_EQ(rows.size(), 19U * 3U * 2U);  // cases x starts x solvers
  int solved = 0;
  for (const auto& row : rows) {
    for (const char* key : {"problem", "n", "start_scale", "solver", "solved", "residual",
                            "f_evals", "j_evals", "ns"}) {
      ASSERT_TRUE(row.contains(key)) << key << " missing in " << row.dump();
    }
    solved += row["solved"].get<bool>();
  }
  EXPECT_GT(solved, 60);
}

TEST(Cli, SuiteTableEndsWithCounts) {
  const CliRun r = run("suite mgh --solvers newton");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("rosenbrock n=2 (start x 100)"), std::string::npos);
  EXPECT_NE(r.out.find("solved (|F|2 <= 1e-8 at the returned point), per solver:"),
            std::string::npos);
  EXPECT_NE(r.out.find("/ 57"), std::string::npos);
  const CliRun bad = run("suite mgh --solvers nonsense");
  EXPECT_NE(bad.status, 0);
  EXPECT_NE(bad.out.find("unknown engine 'nonsense'"), std::string::npos) << bad.out;
  EXPECT_NE(bad.out.find("minpack:hybrj"), std::string::npos) << bad.out;
}

TEST(Cli, ListEngines) {
  const CliRun r = run("list engines");
  ASSERT_EQ(r.status, 0) << r.out;
  for (const char* e : {"picard", "aitken", "steffensen", "anderson", "newton", "ceres", "nlopt",
                        "kinsol:fp-aa2", "gsl:gnewton"}) {
    EXPECT_NE(r.out.find(e), std::string::npos) << e;
  }
  EXPECT_NE(run("list nothing").status, 0);
}

}  // namespace
