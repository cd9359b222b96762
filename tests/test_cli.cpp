// Runs the nlobs executable and checks the contract of `nlobs solve chua-window --json`.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "cli_test_files.hpp"

namespace {

using nlobs::test::CliRun;

CliRun run(const std::string& args) {
  return nlobs::test::run_shell_command(std::string(NLOBS_CLI_PATH) + " " + args);
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

// Output lost to a full disk or a closed pipe used to exit 0 (`nlobs suite … --json >
// /dev/full`): the write to standard output is checked and named.
TEST(Cli, AFailedWriteToStandardOutputIsAnError) {
  for (const char* args :
       {"list", "suite chua-window --solvers newton --json",
        "solve chua-window --engines newton --no-reference", "run chua-fp --steps 20"}) {
    // stderr to the pipe, stdout to the full device.
    std::string command = "(";
    command += NLOBS_CLI_PATH;
    command += " ";
    command += args;
    command += " 2>&1 >/dev/full)";
    const CliRun r = nlobs::test::run_shell_command(command);
    EXPECT_EQ(r.status, 2) << args << ": " << r.out;
    EXPECT_NE(r.out.find("nlobs: error: writing standard output failed: No space left on device"),
              std::string::npos)
        << args << ": " << r.out;
  }
}

// As root, `--csv /dev/null` replaced the device node with a regular file.
TEST(Cli, CsvIntoADeviceIsWrittenNotReplaced) {
  const CliRun r = run("suite chua-window --solvers newton --csv /dev/null");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(std::filesystem::is_character_file("/dev/null"));
  const CliRun full = run("suite chua-window --solvers newton --csv /dev/full");
  EXPECT_EQ(full.status, 2) << full.out;
  EXPECT_NE(full.out.find("writing '/dev/full': No space left on device"), std::string::npos)
      << full.out;
  EXPECT_TRUE(std::filesystem::is_character_file("/dev/full"));
}

// Every positive finite threshold is meaningful; subnormals were refused as "not a finite number".
TEST(Cli, ThresholdTakesEveryPositiveFiniteNumber) {
  EXPECT_EQ(run("suite chua-window --solvers newton --threshold 1e-320").status, 0);
  const CliRun zero = run("suite chua-window --solvers newton --threshold 0");
  EXPECT_EQ(zero.status, 1);
  EXPECT_NE(zero.out.find("'0' is not a finite number > 0"), std::string::npos) << zero.out;
}

// --show-x prints the answer under each row; --time-limit takes seconds in 0.001..86400 and a
// run within it is unchanged (tests/test_suite_answers.cpp ends slow engines with it).
TEST(Cli, ShowXAndTimeLimit) {
  const CliRun shown =
      run("solve mgh/rosenbrock --solvers newton --starts x1 --show-x --time-limit 60");
  EXPECT_EQ(shown.status, 0) << shown.out;
  EXPECT_NE(shown.out.find("    x = [1, 1]\n"), std::string::npos) << shown.out;
  for (const char* bad : {"0", "nan", "-1", "1e9", "soon"}) {
    const CliRun r = run(std::string("solve mgh/rosenbrock --time-limit ") + bad);
    EXPECT_EQ(r.status, 1) << bad << ": " << r.out;
    // The flag, the value given and the range.
    EXPECT_NE(r.out.find(std::string("--time-limit: '") + bad +
                         "' is not a finite number in [0.001, 86400]"),
              std::string::npos)
        << r.out;
  }
}

// --monitor: one line per iteration of each of our engines (SolverOptions::iteration_callback),
// on stderr, the last one at the solution; the references are not monitored.
TEST(Cli, MonitorPrintsEachIteration) {
  const CliRun r = nlobs::test::run_shell_command(
      std::string(NLOBS_CLI_PATH) +
      " solve mgh/rosenbrock --solvers newton:line_search=1,minpack:hybrj --starts x1 --monitor");
  EXPECT_EQ(r.status, 0) << r.out;
  std::istringstream lines(r.out);
  std::string line, last;
  int count = 0;
  while (std::getline(lines, line)) {
    if (line.rfind("newton:line_search=1  rosenbrock/x1  ", 0) != 0) continue;
    EXPECT_NE(line.find("|step| "), std::string::npos) << line;
    ++count;
    last = line;
  }
  EXPECT_GE(count, 2) << r.out;
  EXPECT_EQ(r.out.find("minpack:hybrj  rosenbrock"), std::string::npos) << r.out;
  // Newton ends where |F| is at rounding level: the last line's |F| is tiny.
  const std::size_t at = last.find("|F| ");
  ASSERT_NE(at, std::string::npos) << last;
  EXPECT_LT(std::stod(last.substr(at + 4)), 1e-8) << last;
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
  // Each says which flag, what was given and what is required.
  for (const char* value :
       {"0", "-3", "1000001", "99999999999999999999", "-99999999999999999999"}) {
    const CliRun b = run(std::string("suite bounded --budget ") + value);
    EXPECT_EQ(b.status, 1) << value;
    EXPECT_NE(b.out.find(std::string("--budget: '") + value +
                         "' is out of range: an integer in [1, 1000000] is required"),
              std::string::npos)
        << b.out;
  }
  for (const char* value : {"abc", "1e9", "2.5", "nan"}) {
    const CliRun b = run(std::string("suite bounded --budget ") + value);
    EXPECT_EQ(b.status, 1) << value;
    EXPECT_NE(b.out.find(std::string("--budget: '") + value +
                         "' is not an integer (one in [1, 1000000] is required)"),
              std::string::npos)
        << b.out;
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

TEST(Cli, SolveRunsAnyProblemOfASetBesideTheReferences) {
  const CliRun r = run("solve mgh/rosenbrock --engines newton,kinsol:newton --json");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto rows = nlohmann::json::parse(r.out);
  ASSERT_EQ(rows.size(), 3U * 2U);  // starts x solvers
  for (const auto& row : rows) {
    EXPECT_EQ(row["set"], "mgh");
    EXPECT_EQ(row["problem"], "rosenbrock");
    EXPECT_TRUE(row["solved"].get<bool>()) << row.dump();
    EXPECT_LT(row["error"].get<double>(), 1e-6) << row.dump();  // the known root (1, 1)
  }
  const CliRun table = run("solve chua-window/window --engines anderson --starts x1");
  ASSERT_EQ(table.status, 0) << table.out;
  EXPECT_NE(table.out.find("window n=3 (start x 1)"), std::string::npos) << table.out;
  EXPECT_NE(table.out.find("anderson"), std::string::npos) << table.out;
  // The chua-window table is still there under its own name.
  EXPECT_EQ(run("solve chua-window --no-reference --engines newton").status, 0);
  const CliRun none = run("solve");
  EXPECT_EQ(none.status, 1) << none.out;
  EXPECT_NE(none.out.find("nlobs list problems"), std::string::npos) << none.out;
  const CliRun unknown = run("solve mgh/rosenbrok");
  EXPECT_EQ(unknown.status, 2) << unknown.out;
  EXPECT_NE(unknown.out.find("rosenbrock:n=2"), std::string::npos) << unknown.out;
  const CliRun no_set = run("suite mhg");
  EXPECT_EQ(no_set.status, 2) << no_set.out;
  EXPECT_NE(no_set.out.find("valid problem sets: chua-window, mgh"), std::string::npos)
      << no_set.out;
  EXPECT_NE(run("suite mgh/rosenbrock").out.find("nlobs solve mgh/rosenbrock"), std::string::npos);
  EXPECT_EQ(run("suite mgh --threshold nan").status, 1);
  EXPECT_EQ(run("suite mgh --threshold 0").status, 1);
}

TEST(Cli, ListProblems) {
  const CliRun r = run("list problems");
  ASSERT_EQ(r.status, 0) << r.out;
  for (const char* e : {"chua-window", "window:n=3 (x = G(x)); starts x1 x10", "mgh",
                        "chebyquad:n=9", "rosenbrock:n=2; starts x1 x10 x100; 1 known solution"}) {
    EXPECT_NE(r.out.find(e), std::string::npos) << e << "\n" << r.out;
  }
}

TEST(Cli, ListEngines) {
  const CliRun r = run("list engines");
  ASSERT_EQ(r.status, 0) << r.out;
  for (const char* e : {"picard", "aitken", "steffensen", "anderson", "newton", "ceres", "nlopt",
                        "kinsol:fp-aa2", "gsl:gnewton"}) {
    EXPECT_NE(r.out.find(e), std::string::npos) << e;
  }
  // The reference solvers are engines of the registry, with the common keys they do not take.
  EXPECT_NE(r.out.find("  minpack — MINPACK hybrj"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("not taken of the options of every engine: step_tolerance max_iterations "
                       "progress_window"),
            std::string::npos)
      << r.out;
  EXPECT_NE(run("list nothing").status, 0);
}

// Exit status 1: the command line is wrong; 2: the run failed (docs/cli.md).
TEST(Cli, ExitStatusSaysWhetherTheCommandLineOrTheRunFailed) {
  for (const char* args :
       {"run chua-fp --steps abc", "run chua-fp --steps 0", "run chua-fp --seed -1",
        "run chua-fp --noise inf", "run chua-fp --noise nan", "run chua-fp --noise -1",
        "run chua-fp --bogus", "run", "run chua-fp --plot-timeout 0",
        "run chua-fp --plot-timeout nan"}) {
    const CliRun r = run(args);
    EXPECT_EQ(r.status, 1) << args << ": " << r.out;
  }
  // inf and nan get the same message.
  const std::string inf = run("run chua-fp --noise inf").out,
                    nan = run("run chua-fp --noise nan").out;
  EXPECT_NE(inf.find("'inf' is not a finite number >= 0"), std::string::npos) << inf;
  EXPECT_NE(nan.find("'nan' is not a finite number >= 0"), std::string::npos) << nan;
  for (const char* args : {"run no-such-scenario", "run chua-fp --data /nonexistent.csv",
                           "run /tmp", "solve chua-window --engines bogus"}) {
    const CliRun r = run(args);
    EXPECT_EQ(r.status, 2) << args << ": " << r.out;
    EXPECT_NE(r.out.find("nlobs: error: "), std::string::npos) << r.out;
  }
  EXPECT_NE(run("run /tmp").out.find("scenario file '/tmp' is a directory"), std::string::npos);
  EXPECT_EQ(run("--help").status, 0);
  // suite --help names every set `list problems` lists (the lines "  NAME — ...").
  const CliRun suite_help = run("suite --help"), sets = run("list problems");
  EXPECT_EQ(suite_help.status, 0);
  std::istringstream lines(sets.out);
  int listed = 0;
  for (std::string line; std::getline(lines, line);) {
    const std::size_t dash = line.find(" \u2014 ");
    if (line.rfind("  ", 0) != 0 || line[2] == ' ' || dash == std::string::npos) continue;
    const std::string set = line.substr(2, dash - 2);
    ++listed;
    EXPECT_NE(suite_help.out.find(set + ","), std::string::npos) << set << "\n" << suite_help.out;
  }
  EXPECT_GE(listed, 4) << sets.out;
  // The threshold is on the scaled residual, and the scaled problems say so (combustion).
  EXPECT_NE(sets.out.find("solved at |D_f F|2 <= 1e-08 (D_f = diag(f_scale)"), std::string::npos)
      << sets.out;
  EXPECT_NE(sets.out.find("combustion:n=10; starts"), std::string::npos) << sets.out;
  EXPECT_NE(sets.out.find("scaled (u_scale, f_scale)"), std::string::npos) << sets.out;
  // An engine spec echoed in an error is an excerpt.
  const CliRun spec =
      run("solve chua-window --no-reference --engines anderson:" + std::string(5000, 'm') + "=1");
  EXPECT_EQ(spec.status, 2);
  EXPECT_LT(spec.out.size(), 2000U) << spec.out.size();
}

// SIGTERM while gnuplot writes a PNG: the handler stops gnuplot, removes every temporary and the
// process ends by the signal; the data files written before are whole, and summary.json absent.
TEST(Cli, SigtermLeavesNoTemporaryFiles) {
  namespace fs = std::filesystem;
  const fs::path bin = nlobs::test::scratch_path("nlobs_test_cli", "slow_gnuplot_bin");
  const fs::path dir = nlobs::test::scratch_path("nlobs_test_cli", "interrupted");
  fs::remove_all(dir);
  fs::remove(dir.parent_path() / "gnuplot.pid");
  fs::create_directories(bin);
  // It starts the first PNG its script names, then never finishes.
  nlobs::test::write_file(bin / "gnuplot",
                          "#!/bin/sh\n"
                          "out=$(sed -n \"s/^set output '\\(.*\\)'$/\\1/p\" \"$1\" | head -n 1)\n"
                          "echo $$ > ../gnuplot.pid\nprintf partial > \"$out\"\n"
                          "exec /bin/sleep 60\n");
  fs::permissions(bin / "gnuplot", fs::perms::owner_all);
  std::string program = NLOBS_CLI_PATH, run_word = "run", scenario = "chua-fp", steps = "--steps",
              count = "300", out = "--out", where = dir.string();
  std::vector<char*> argv = {program.data(), run_word.data(), scenario.data(), steps.data(),
                             count.data(),   out.data(),      where.data(),    nullptr};
  std::string path = "PATH=" + bin.string() + ":/usr/bin:/bin";
  std::vector<char*> env = {path.data(), nullptr};
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  ASSERT_EQ(posix_spawn(&pid, program.c_str(), &actions, nullptr, argv.data(), env.data()), 0);
  posix_spawn_file_actions_destroy(&actions);
  // The PNG's temporary (`.states.png.tmp-XXXXXX`), once the fake gnuplot has written into it.
  const auto started = [&dir] {
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
      const std::string name = it->path().filename().string();
      if (name.rfind(".states.png.tmp-", 0) == 0 && fs::file_size(it->path(), ec) > 0) return true;
    }
    return false;
  };
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (!started() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_TRUE(started()) << "the fake gnuplot never started";
  ::kill(pid, SIGTERM);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM) << status;
  for (const auto& e : fs::directory_iterator(dir)) {
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
    EXPECT_NE(e.path().extension(), ".png") << e.path();
  }
  EXPECT_FALSE(fs::exists(dir / "summary.json"));
  EXPECT_GT(fs::file_size(dir / "trajectories.csv"), 1000U);
  // The handler stopped gnuplot (and reaped it) before the process ended.
  std::ifstream pid_file(dir.parent_path() / "gnuplot.pid");
  pid_t gnuplot = 0;
  ASSERT_TRUE(pid_file >> gnuplot);
  EXPECT_NE(::kill(gnuplot, 0), 0) << "gnuplot " << gnuplot << " still runs";
}

}  // namespace
