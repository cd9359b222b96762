// Our minpack:hybrj row against MINPACK's published test-driver output (cminpack's hyjdrv,
// tests/data/minpack/): configured as the driver configures hybrj1 (mode 2, diag = 1, factor
// 100, xtol = √ε, maxfev = 100 (n + 1)), on the 50 runs whose problem and size our MGH set has.
// The problems are right when the initial ‖F‖₂ agree; the row is MINPACK as published when every
// run has the same outcome (‖F‖₂ ≤ 1e-8 or not) and evaluation counts of the same order.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "nlobs/reference/root_reference.hpp"
#include "nlobs/registry/problem_sets/mgh_problems.hpp"
#include "nlobs/solvers/builtin_engines.hpp"
#include "nlobs/solvers/root_adapter.hpp"

namespace nlobs::reference {
namespace {

struct PublishedRun {
  int problem = 0, n = 0;
  double scale = 1.0;  // the standard start times 1, 10, 100: the driver's order
  double initial_norm = NAN, final_norm = NAN;
  long f_evals = 0, j_evals = 0;
  int info = 0;
};

// Reads the driver's blocks: "problem P dimension N", "initial l2 norm ...", "final l2 norm
// ...", "number of function evaluations", "number of jacobian evaluations", "exit parameter".
std::vector<PublishedRun> read_driver_output(const std::string& path) {
  std::ifstream in(path);
  std::vector<PublishedRun> runs;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::string first;
    words >> first;
    if (first == "problem") {
      PublishedRun r;
      std::string dimension;
      words >> r.problem >> dimension >> r.n;
      int earlier = 0;
      for (const PublishedRun& p : runs) earlier += p.problem == r.problem && p.n == r.n;
      r.scale = std::pow(10.0, earlier);
      runs.push_back(r);
    } else if (runs.empty()) {
      continue;
    } else if (first == "initial") {
      std::string l2, norm, of, the, residuals;
      words >> l2 >> norm >> of >> the >> residuals >> runs.back().initial_norm;
    } else if (first == "final" && line.find("l2 norm") != std::string::npos) {
      std::string l2, norm, of, the, residuals;
      words >> l2 >> norm >> of >> the >> residuals >> runs.back().final_norm;
    } else if (line.find("function evaluations") != std::string::npos) {
      runs.back().f_evals = std::stol(line.substr(line.find_last_of(' ') + 1));
    } else if (line.find("jacobian evaluations") != std::string::npos) {
      runs.back().j_evals = std::stol(line.substr(line.find_last_of(' ') + 1));
    } else if (line.find("exit parameter") != std::string::npos) {
      runs.back().info = std::stoi(line.substr(line.find_last_of(' ') + 1));
    }
  }
  return runs;
}

bool have_case(int problem, int n) {
  for (const MghCase& c : mgh_cases()) {
    if (c.number == problem && c.n == n) return true;
  }
  return false;
}

TEST(MinpackReference, TheDriverOutputReadsAsPublished) {
  const auto runs = read_driver_output(NLOBS_MINPACK_REFERENCE);
  ASSERT_EQ(runs.size(), 55u);
  for (const PublishedRun& r : runs) {
    EXPECT_TRUE(std::isfinite(r.initial_norm) && std::isfinite(r.final_norm)) << r.problem;
    EXPECT_GT(r.f_evals, 0);
  }
  EXPECT_EQ(std::count_if(runs.begin(), runs.end(),
                          [](const PublishedRun& r) { return have_case(r.problem, r.n); }),
            50);
}

TEST(MinpackReference, OurHybrjRowIsMinpackAsPublishedRunByRun) {
  const auto runs = read_driver_output(NLOBS_MINPACK_REFERENCE);
  int compared = 0, same_outcome = 0, published_solved = 0, ours_solved = 0;
  std::vector<double> ratios;
  for (const PublishedRun& r : runs) {
    if (!have_case(r.problem, r.n)) continue;
    ++compared;
    const MghCase c = mgh_case(r.problem, r.n);
    Eigen::VectorXd x = c.start(r.scale), f(r.n);
    c.problem.evaluate(x, f);
    SCOPED_TRACE(c.name + " n=" + std::to_string(r.n) + " x" + std::to_string(int(r.scale)));
    EXPECT_NEAR(f.norm(), r.initial_norm, 1e-7 * r.initial_norm);  // the same problem

    ReferenceOptions driver;
    driver.max_evaluations = 100 * (r.n + 1);
    const ReferenceResult ours = solve_minpack_hybrj(c.problem, x, driver);
    c.problem.evaluate(x, f);
    const bool solved = x.allFinite() && f.norm() <= 1e-8;
    const bool published = r.final_norm <= 1e-8;
    EXPECT_EQ(solved, published) << "ours |F|2 " << f.norm() << " (" << ours.status
                                 << "), published " << r.final_norm << " (info " << r.info << ")";
    same_outcome += solved == published;
    published_solved += published;
    ours_solved += solved;
    const long our_evals = ours.f_evals - 1;  // check_answer's evaluation is not hybrj's
    ratios.push_back(static_cast<double>(our_evals) / static_cast<double>(r.f_evals));
    // Same order: the C port and the Fortran differ by up to 40 % on long runs, and our AD
    // Jacobians differ from the driver's hand-coded ones in the last bits. Measured: equal on 37
    // of the 50 runs, median ratio 1.000; the extremes chebyquad n=7 x100 (128 against 48, the
    // Fortran 56) and discrete_integral_equation n=10 x100 (19 against 48).
    EXPECT_LE(our_evals, 3 * r.f_evals) << "published " << r.f_evals;
    EXPECT_GE(3 * our_evals, r.f_evals) << "published " << r.f_evals;
  }
  EXPECT_EQ(compared, 50);
  EXPECT_EQ(same_outcome, 50);
  EXPECT_EQ(ours_solved, published_solved);
  std::sort(ratios.begin(), ratios.end());
  const int exact = static_cast<int>(
      std::count_if(ratios.begin(), ratios.end(), [](double q) { return q == 1.0; }));
  EXPECT_GE(exact, 30);  // the same iterations to the last evaluation on most runs
  EXPECT_NEAR(ratios[ratios.size() / 2], 1.0, 0.05);
  std::printf(
      "minpack:hybrj vs cminpack's hyjdrv: %d of %d runs solved in both; F evaluations "
      "ours/published: median %.3f, range %.3f..%.3f, equal on %d runs\n",
      ours_solved, compared, ratios[ratios.size() / 2], ratios.front(), ratios.back(), exact);
}

// Our own engines on the same 50 runs, judged like the suite (budget 1000 (n + 1), ‖F‖₂ ≤ 1e-8):
// dogleg (MINPACK's method) and auto must solve every run MINPACK's published output solves,
// auto at least 48 of the 50 (issue "Root finding that beats MINPACK").
TEST(MinpackReference, DoglegAndAutoSolveEveryRunMinpackSolves) {
  const auto runs = read_driver_output(NLOBS_MINPACK_REFERENCE);
  for (const char* spec : {"dogleg", "auto"}) {
    int solved = 0, missed_published = 0;
    for (const PublishedRun& r : runs) {
      if (!have_case(r.problem, r.n)) continue;
      const MghCase c = mgh_case(r.problem, r.n);
      SolverOptions o;
      o.stop.step_tolerance = 1e-12;
      o.stop.residual_tolerance = 1e-10;
      o.stop.max_evaluations = 1000 * (r.n + 1);
      const auto engine = EngineRegistry<>::global().create(spec, o);
      Eigen::VectorXd x = c.start(r.scale), f(r.n);
      const Summary s = engine->solve(to_fixed_point(c.problem), x);
      c.problem.evaluate(x, f);
      const bool ok = x.allFinite() && f.norm() <= 1e-8;
      solved += ok;
      if (r.final_norm <= 1e-8 && !ok) {
        ++missed_published;
        ADD_FAILURE() << spec << " misses " << c.name << " n=" << r.n << " x" << r.scale
                      << ", which MINPACK solves: " << s.brief_report();
      }
    }
    EXPECT_EQ(missed_published, 0) << spec;
    // Measured: dogleg 46 (MINPACK's 44 and Powell badly scaled x10, Broyden tridiagonal x1),
    // auto 49 (Chebyquad n = 8, which has no root, is the one left).
    EXPECT_GE(solved, 46) << spec;
    if (std::string(spec) == "auto") {
      EXPECT_GE(solved, 48);
    }
    std::printf("%s: %d of the 50 shared runs (MINPACK 44)\n", spec, solved);
  }
}

}  // namespace
}  // namespace nlobs::reference
