// StopCriteria::progress_window (a Jacobian-based engine ends stagnated once that many
// evaluations of F have not brought ‖F‖₂ below 0.999 × its value at the last such fall) and
// auto's shared local minimum (PolyalgorithmOptions::shared_minimum, Status::kLocalMinimum).
// The evaluations after the last fall are counted here, by the test's own F, not taken from the
// engines. Problems nlobs does not ship: x² + 1 (no real root; a minimum of |F| at 0), a wavy
// valley with a local minimum of ‖F‖ that is not a root, a valley whose infimum lies at infinity,
// and a cubic.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "nlobs/solvers/engine_registry.hpp"
#include "test_support.hpp"

namespace nlobs {
namespace {

struct Case {
  std::string name;
  std::function<void(const Eigen::VectorXd&, Eigen::VectorXd&)> f;
  std::function<void(const Eigen::VectorXd&, Eigen::MatrixXd&)> jacobian;
  Eigen::VectorXd x0;
};

std::vector<Case> no_root_cases() {
  std::vector<Case> cases;
  cases.push_back({"x^2 + 1",
                   [](const Eigen::VectorXd& x, Eigen::VectorXd& f) {
                     f.resize(1);
                     f[0] = x[0] * x[0] + 1.0;
                   },
                   [](const Eigen::VectorXd& x, Eigen::MatrixXd& j) {
                     j.resize(1, 1);
                     j(0, 0) = 2.0 * x[0];
                   },
                   Eigen::VectorXd::Constant(1, 1.3)});
  // F = (10 (y − x²), 1.2 + sin 3x + 0.1 y²): the second component never vanishes.
  cases.push_back({"wavy valley",
                   [](const Eigen::VectorXd& x, Eigen::VectorXd& f) {
                     f.resize(2);
                     f[0] = 10.0 * (x[1] - x[0] * x[0]);
                     f[1] = 1.2 + std::sin(3.0 * x[0]) + 0.1 * x[1] * x[1];
                   },
                   [](const Eigen::VectorXd& x, Eigen::MatrixXd& j) {
                     j.resize(2, 2);
                     j << -20.0 * x[0], 10.0, 3.0 * std::cos(3.0 * x[0]), 0.2 * x[1];
                   },
                   (Eigen::VectorXd(2) << -1.2, 1.0).finished()});
  // F = (xy − 1, xy − 2 + e^{−x}): no root; ‖F‖ → 0 only as x → 0 with y = 1/x → ∞ (eco-like:
  // y runs away while ‖F‖ crawls down — progress that never ends, which the window must not cut).
  cases.push_back({"valley to infinity",
                   [](const Eigen::VectorXd& x, Eigen::VectorXd& f) {
                     f.resize(2);
                     f[0] = x[0] * x[1] - 1.0;
                     f[1] = x[0] * x[1] - 2.0 + std::exp(-x[0]);
                   },
                   [](const Eigen::VectorXd& x, Eigen::MatrixXd& j) {
                     j.resize(2, 2);
                     j << x[1], x[0], x[1] - std::exp(-x[0]), x[0];
                   },
                   Eigen::VectorXd::Constant(2, 2.0)});
  return cases;
}

// Solves `c` with `spec`, recording ‖F‖₂ at every evaluation of G; idle = the evaluations
// after the last one that fell below 0.999 × the value at the fall before it.
struct Outcome {
  Summary summary;
  long idle = 0;          // after the last fall
  long longest_idle = 0;  // the longest stretch without one
  long evaluations = 0;
};
Outcome run(const Case& c, const std::string& spec, int max_evaluations = 20000) {
  std::vector<double> norms;
  const Index n = c.x0.size();
  auto g = [&](const Eigen::VectorXd& x, Eigen::VectorXd& out) {
    Eigen::VectorXd f;
    c.f(x, f);
    norms.push_back(f.allFinite() ? f.norm() : std::numeric_limits<double>::infinity());
    out = x + f;
  };
  auto dg = [&](const Eigen::VectorXd& x, Eigen::MatrixXd& jac) {
    c.jacobian(x, jac);
    jac += Eigen::MatrixXd::Identity(n, n);
  };
  const auto problem = FixedPointProblem<Dynamic>::with_jacobian(g, dg, n);
  SolverOptions o;
  o.stop.max_evaluations = max_evaluations;
  auto engine = EngineRegistry<Dynamic>::global().create(spec, o);
  Eigen::VectorXd x = c.x0;
  Outcome r;
  r.summary = engine->solve(problem, x);
  double anchor = std::numeric_limits<double>::infinity();
  long last_fall = 0;
  for (std::size_t i = 0; i < norms.size(); ++i) {
    if (norms[i] < 0.999 * anchor) {
      anchor = norms[i];
      last_fall = static_cast<long>(i) + 1;
    }
    r.longest_idle = std::max(r.longest_idle, static_cast<long>(i) + 1 - last_fall);
  }
  r.evaluations = static_cast<long>(norms.size());
  r.idle = r.evaluations - last_fall;
  return r;
}

TEST(ProgressWindow, CountsEvaluationsSinceTheLastMeaningfulFall) {
  ProgressWindow w;
  w.start(3);
  w.saw(10.0);   // the first finite value is a fall from +inf
  w.saw(9.995);  // above 0.999 × 10: no progress
  w.saw(std::numeric_limits<double>::quiet_NaN());
  EXPECT_FALSE(w.expired());
  w.saw(std::numeric_limits<double>::infinity());
  EXPECT_TRUE(w.expired());  // three evaluations since the fall to 10
  EXPECT_NE(w.message().find("progress_window"), std::string::npos) << w.message();
  EXPECT_NE(w.message().find("0.999 x 10 "), std::string::npos) << w.message();  // the anchor
  w.saw(9.989);  // below 0.999 × 10: progress, the window starts again
  EXPECT_FALSE(w.expired());

  // A crawl of 1e-4 relative per evaluation falls 0.1 % every ten or so: never expires.
  ProgressWindow crawl;
  crawl.start(20);
  double norm = 1.0;
  for (int i = 0; i < 1000; ++i, norm *= 1.0 - 1e-4) {
    crawl.saw(norm);
    ASSERT_FALSE(crawl.expired()) << i;
  }

  ProgressWindow off;
  off.start(0);
  for (int i = 0; i < 1000; ++i) off.saw(1.0);
  EXPECT_FALSE(off.expired());
}

TEST(ProgressWindow, NoEngineSpendsMoreThanAWindowPastItsLastFall) {
  for (const Case& c : no_root_cases()) {
    const bool endless_descent = c.name == "valley to infinity";
    std::map<std::string, long> alone;  // each engine's evaluations, run alone from x0
    for (const std::string& spec : test::kJacobianEngineSpecs) {
      const Outcome r = run(c, spec);
      SCOPED_TRACE(c.name + ", " + spec + ": " + std::string(to_string(r.summary.status)) + " " +
                   r.summary.message);
      EXPECT_FALSE(r.summary.usable());
      if (r.summary.status != Status::kMaxIterations &&
          r.summary.status != Status::kMaxEvaluations) {
        EXPECT_FALSE(r.summary.message.empty());  // every other stop names its rule
      }
      if (!endless_descent) {  // there ‖F‖ keeps falling: a budget may end it
        EXPECT_NE(r.summary.status, Status::kMaxEvaluations);
        EXPECT_NE(r.summary.status, Status::kMaxIterations);
      }
      EXPECT_EQ(r.evaluations, r.summary.function_evaluations);
      if (spec != "auto") {
        EXPECT_LE(r.idle, 50);
        alone[spec] = r.evaluations;
        continue;
      }
      // Each stage restarts from x0, so what a later stage spends descending towards a minimum
      // an earlier one found counts here as idle (docs/solvers.md, "Evaluations past
      // progress"). But inside auto each stage stops exactly as it does alone: auto's cost is
      // the sum of the stages it ran, as its message names them, and no more.
      if (endless_descent) continue;  // (there the shared budget ends the last stage early)
      std::set<std::string> ran;
      std::string history = r.summary.message;
      for (std::size_t at = 0; at < history.size();) {
        const std::size_t end = std::min(history.find("; ", at), history.size());
        const std::string item = history.substr(at, end - at);
        const std::string first = item.substr(0, item.find(' '));
        if (alone.count(first) != 0) ran.insert(first);
        at = end + 2;
      }
      long sum = 0;
      for (const std::string& stage : ran) sum += alone[stage];
      EXPECT_GE(ran.size(), 2u);
      EXPECT_EQ(r.evaluations, sum);
    }
  }
}

TEST(ProgressWindow, WithoutItAHopelessRunSpendsItsBudget) {
  const Case c = no_root_cases()[0];  // x² + 1: Newton's iterates wander, pseudo-time flows on
  for (const std::string engine : {"newton", "pseudo-transient"}) {
    const Outcome on = run(c, engine);
    EXPECT_EQ(on.summary.status, Status::kStagnated) << engine;
    EXPECT_NE(on.summary.message.find("StopCriteria::progress_window"), std::string::npos)
        << on.summary.message;
    EXPECT_EQ(on.idle, 50) << engine;
    EXPECT_LE(on.evaluations, 200) << engine;

    const Outcome off = run(c, engine + ":progress_window=0", 3000);
    EXPECT_TRUE(off.summary.status == Status::kMaxIterations ||
                off.summary.status == Status::kMaxEvaluations)
        << engine << ": " << to_string(off.summary.status);
    EXPECT_GT(off.idle, 2000) << engine;
  }
  // A longer window waits longer.
  EXPECT_EQ(run(c, "newton:progress_window=200").idle, 200);
}

TEST(ProgressWindow, ARunThatKeepsFallingIsNotCut) {
  // Newton on X² = A (Hammarling's matrix square root, 2×2, from the identity): steps grow from
  // 0.5 to 15 while ‖F‖ falls at each; converged.
  auto f = [](const Eigen::VectorXd& x, Eigen::VectorXd& out) {
    const Eigen::Map<const Eigen::Matrix2d> m(x.data());
    Eigen::Matrix2d a;
    a << 1e-4, 1.0, 0.0, 1e-4;
    const Eigen::Matrix2d r = m * m - a;
    out = Eigen::Map<const Eigen::VectorXd>(r.data(), 4);
  };
  const auto problem = to_fixed_point(RootProblem<Dynamic>::from_map(f, 4, 4));
  SolverOptions o = test::tolerance(1e-12);
  o.stop.progress_window = 5;  // a short window: every iteration of this run still falls
  auto engine = EngineRegistry<Dynamic>::global().create("newton", o);
  Eigen::VectorXd x(4);
  x << 1.0, 0.0, 0.0, 1.0;
  const Summary s = engine->solve(problem, x);
  EXPECT_EQ(s.status, Status::kConverged) << s.message;
}

TEST(ProgressWindow, ALeastSquaresMinimumIsNotStagnation) {
  // F = (x − 100, x + 100, x³ − 1): min ‖F‖ ≈ 141 at x = 0. From 0.5, ‖F‖₂ moves by ~1e-5
  // relative per step: no window's 0.1 % fall, yet the iteration converges. A least-squares
  // run (more rows than unknowns) ignores the window, however short.
  const auto problem = RootProblem<Dynamic, Dynamic>::with_autodiff(
      [](const auto& x) {
        using T = typename std::decay_t<decltype(x)>::Scalar;
        Eigen::Matrix<T, Eigen::Dynamic, 1> f(3);
        f << x[0] - 100.0, x[0] + 100.0, x[0] * x[0] * x[0] - 1.0;
        return f;
      },
      1, 3);
  for (const int window : {1, 2, 50}) {
    SolverOptions o;
    o.stop.progress_window = window;
    auto engine = EngineRegistry<Dynamic>::global().create("levenberg-marquardt", o);
    Eigen::VectorXd x = Eigen::VectorXd::Constant(1, 0.5);
    const Summary s = engine->solve_least_squares(problem, x);
    EXPECT_EQ(s.status, Status::kConverged) << window << ": " << s.message;
    EXPECT_TRUE(s.usable()) << window;
    EXPECT_NEAR(x[0], 0.0, 1e-6) << window;
  }
}

TEST(ProgressWindow, InvalidValuesAreNamed) {
  StopCriteria c;
  c.progress_window = -1;
  EXPECT_NE(test::message_of([&] { validate(c); }).find("progress_window = -1"), std::string::npos);
  auto& registry = EngineRegistry<Dynamic>::global();
  EXPECT_NE(test::message_of([&] {
              registry.create("newton:progress_window=-1");
            }).find("progress_window"),
            std::string::npos);
  EXPECT_NE(test::message_of([&] {
              registry.create("dogleg:progress_window=1e99");
            }).find("progress_window"),
            std::string::npos);
  EXPECT_NE(
      test::message_of([&] { registry.create("auto:shared_minimum=-2"); }).find("shared_minimum"),
      std::string::npos);
  EXPECT_EQ(registry.create("newton:progress_window=7")->options().stop.progress_window, 7);
}

TEST(SharedMinimum, AutoStopsWhereTwoMethodsMeetAtALocalMinimum) {
  const Case c = no_root_cases()[1];  // the wavy valley: dogleg and LM end at one minimum
  const Outcome shared = run(c, "auto");
  EXPECT_EQ(shared.summary.status, Status::kLocalMinimum) << shared.summary.message;
  EXPECT_FALSE(shared.summary.usable());
  EXPECT_NE(shared.summary.message.find("a local minimum of |F| that is not a root"),
            std::string::npos)
      << shared.summary.message;
  EXPECT_NE(shared.summary.message.find("not run: pseudo-transient"), std::string::npos)
      << shared.summary.message;
  EXPECT_NE(shared.summary.unusable_reason().find("local_minimum with |F|"), std::string::npos)
      << shared.summary.unusable_reason();

  // Off: every stage runs, and the answer is no better.
  const Outcome all = run(c, "auto:shared_minimum=0");
  EXPECT_NE(all.summary.status, Status::kLocalMinimum);
  EXPECT_GT(all.evaluations, shared.evaluations);
  EXPECT_GE(all.summary.residual_norm, shared.summary.residual_norm * (1.0 - 1e-3));

  // Where the stages stop at different points (along the valley to infinity), nothing is shared.
  const Outcome apart = run(no_root_cases()[2], "auto");
  EXPECT_NE(apart.summary.status, Status::kLocalMinimum) << apart.summary.message;
}

TEST(SharedMinimum, WhatItCostsAFlowThatClimbsOutOfTheMinimum) {
  // F = x³ − 3x + 3 from 1.5: a minimum of |F| at x = 1 (|F| = 1) between x0 and the root
  // −2.1038; ẋ = −F climbs over the hill (|F| = 3 at 0) to the root. Dogleg and LM stop at the
  // minimum; with both rules on, auto stops there too. Off, its last stage reaches the root.
  const Case cubic{"cubic",
                   [](const Eigen::VectorXd& x, Eigen::VectorXd& f) {
                     f.resize(1);
                     f[0] = x[0] * x[0] * x[0] - 3.0 * x[0] + 3.0;
                   },
                   [](const Eigen::VectorXd& x, Eigen::MatrixXd& j) {
                     j.resize(1, 1);
                     j(0, 0) = 3.0 * x[0] * x[0] - 3.0;
                   },
                   Eigen::VectorXd::Constant(1, 1.5)};
  const Outcome stopped = run(cubic, "auto");
  EXPECT_EQ(stopped.summary.status, Status::kLocalMinimum) << stopped.summary.message;
  EXPECT_LE(stopped.evaluations, 50);
  const Outcome patient = run(cubic, "auto:shared_minimum=0,progress_window=0");
  EXPECT_EQ(patient.summary.status, Status::kConverged) << patient.summary.message;
  EXPECT_EQ(patient.summary.stage, "pseudo-transient");
  const Outcome flow = run(cubic, "pseudo-transient:progress_window=0");
  EXPECT_TRUE(flow.summary.usable()) << flow.summary.message;
  EXPECT_GT(flow.longest_idle, 50);  // it climbed: more than a window without a fall
}

TEST(SharedMinimum, ASolvableProblemIsSolved) {
  // The wavy valley shifted to have a root: F = (10 (y − x²), sin 3x + 0.1 y² − 0.05).
  Case c = no_root_cases()[1];
  c.f = [](const Eigen::VectorXd& x, Eigen::VectorXd& f) {
    f.resize(2);
    f[0] = 10.0 * (x[1] - x[0] * x[0]);
    f[1] = std::sin(3.0 * x[0]) + 0.1 * x[1] * x[1] - 0.05;
  };
  const Outcome r = run(c, "auto");
  EXPECT_EQ(r.summary.status, Status::kConverged) << r.summary.message;
  EXPECT_TRUE(r.summary.usable());
}

}  // namespace
}  // namespace nlobs
