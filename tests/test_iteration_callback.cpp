// SolverOptions::iteration_callback: every built-in engine calls it after each iteration with
// what its trace records, kStop ends the solve with Status::kStoppedByCallback at the current
// iterate (judged as any run cut short), an exception it throws leaves solve() unchanged, and
// `auto` stops with the stage that was stopped. Engine::set_record_trace reaches inner engines.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "nlobs/solvers/builtin_engines.hpp"
#include "test_support.hpp"

namespace nlobs {
namespace {

// A contraction nlobs does not ship: G(x) = (½ cos x₂, ½ sin x₁ + ¼), fixed point near
// (0.4856, 0.4834); every engine solves it from (1, −1), the fixed-point ones as well.
FixedPointProblem<> coupled_cosine() {
  return FixedPointProblem<>::with_autodiff(
      [](const auto& x, auto& g) {
        using std::cos, std::sin;
        g[0] = 0.5 * cos(x[1]);
        g[1] = 0.5 * sin(x[0]) + 0.25;
      },
      2);
}

// The same at the fixed size 2.
FixedPointProblem<2> coupled_cosine_fixed() {
  return FixedPointProblem<2>::with_autodiff(
      [](const auto& v, auto& g) {
        using std::cos, std::sin;
        g[0] = 0.5 * cos(v[1]);
        g[1] = 0.5 * sin(v[0]) + 0.25;
      },
      2);
}

Vector<> start() {
  return (Vector<>(2) << 1.0, -1.0).finished();
}

SolverOptions tight() {
  SolverOptions o;
  o.stop.step_tolerance = 1e-12;
  o.stop.residual_tolerance = 1e-11;
  return o;
}

// The engines whose iterations are their own (Ceres reports its iteration 0, NLopt evaluations,
// auto its stages').
const std::vector<std::string> kOwnLoopEngines = {
    "picard", "aitken", "steffensen", "anderson", "newton", "newton:line_search=1",
    "newton:trust_region=1", "dogleg", "broyden", "levenberg-marquardt",
    // The residual flow dx/dt = -F = x - G(x)
    // runs away from a contraction's fixed point
    // (J_F near -I; it stagnates here): the
    // fixed-point flow is this problem's.
    "pseudo-transient:flow=fixed-point"};

TEST(IterationCallback, EveryEngineReportsEachIterationAsItsTraceRecordsIt) {
  auto& registry = EngineRegistry<Dynamic>::global();
  for (const std::string& spec : kOwnLoopEngines) {
    std::vector<IterationRecord> seen;
    std::vector<Eigen::VectorXd> points;
    SolverOptions o = tight();
    o.record_trace = true;
    o.iteration_callback = [&](const IterationRecord& r) {
      seen.push_back(r);
      points.emplace_back(r.x);  // x is valid during the call only: copied
      return IterationDecision::kContinue;
    };
    auto engine = registry.create(spec, o);
    Vector<> x = start();
    const Summary s = engine->solve(coupled_cosine(), x);
    ASSERT_EQ(s.status, Status::kConverged) << spec << '\n' << s.full_report();
    ASSERT_FALSE(seen.empty()) << spec;
    ASSERT_EQ(seen.size(), s.trace.size()) << spec;
    for (std::size_t k = 0; k < seen.size(); ++k) {
      EXPECT_EQ(seen[k].iteration, s.trace[k].iteration) << spec;
      EXPECT_EQ(seen[k].step_norm, s.trace[k].step_norm) << spec;
      EXPECT_EQ(seen[k].residual_norm, s.trace[k].residual_norm) << spec;
      EXPECT_EQ(points[k], s.trace[k].x) << spec;
    }
    // The last residual the engine evaluated (for anderson, at the point extrapolated from).
    EXPECT_LE(seen.back().residual_norm, 1e-9) << spec;
  }
}

// Engine::set_record_trace turns the trace on and off between solves, through the engines that
// hold others: auto's stages, Newton's trust region, a Dynamic engine served at a fixed size.
TEST(RecordTrace, SetRecordTraceReachesEveryInnerEngine) {
  auto& registry = EngineRegistry<Dynamic>::global();
  for (const std::string spec : {"newton", "newton:trust_region=1", "auto", "dogleg", "broyden",
                                 "levenberg-marquardt", "anderson"}) {
    auto engine = registry.create(spec, tight());
    const auto solve = [&] {
      Vector<> x = start();
      const Summary s = engine->solve(coupled_cosine(), x);
      EXPECT_EQ(s.status, Status::kConverged) << spec << '\n' << s.full_report();
      return s;
    };
    EXPECT_TRUE(solve().trace.empty()) << spec;
    engine->set_record_trace(true);
    EXPECT_TRUE(engine->options().record_trace) << spec;
    if (const auto* poly = dynamic_cast<const PolyalgorithmEngine<Dynamic>*>(engine.get())) {
      for (const auto& stage : poly->stages()) EXPECT_TRUE(stage->options().record_trace);
    }
    const Summary traced = solve();
    EXPECT_FALSE(traced.trace.empty()) << spec;
    engine->set_record_trace(false);
    EXPECT_TRUE(solve().trace.empty()) << spec;
  }
  DynamicSizeEngine<2> fixed(std::make_unique<NewtonEngine<>>(NewtonOptions{}, tight()));
  const FixedPointProblem<2> problem = coupled_cosine_fixed();
  fixed.set_record_trace(true);
  Vector<2> x(1.0, -1.0);
  const Summary s = fixed.solve(problem, x);
  EXPECT_EQ(s.status, Status::kConverged) << s.full_report();
  EXPECT_FALSE(s.trace.empty());
  fixed.set_record_trace(false);
  x = Vector<2>(1.0, -1.0);
  EXPECT_TRUE(fixed.solve(problem, x).trace.empty());
}

TEST(IterationCallback, StopEndsTheSolveAtTheCurrentIterate) {
  auto& registry = EngineRegistry<Dynamic>::global();
  std::vector<std::string> specs = kOwnLoopEngines;
  specs.insert(specs.end(), {"ceres", "ceres:dogleg", "nlopt:LN_BOBYQA", "nlopt:LD_SLSQP"});
  for (const std::string& spec : specs) {
    int calls = 0;
    Eigen::VectorXd last;
    SolverOptions o = tight();
    o.iteration_callback = [&](const IterationRecord& r) {
      last = r.x;
      return ++calls == 2 ? IterationDecision::kStop : IterationDecision::kContinue;
    };
    auto engine = registry.create(spec, o);
    Vector<> x = start();
    const Summary s = engine->solve(coupled_cosine(), x);
    EXPECT_EQ(s.status, Status::kStoppedByCallback) << spec << '\n' << s.full_report();
    EXPECT_EQ(calls, 2) << spec;  // not called again once it said stop
    EXPECT_TRUE(x.allFinite()) << spec;
    // Two iterations from (1, -1) are far from the fixed point: cut short, not usable.
    EXPECT_FALSE(s.usable()) << spec;
    EXPECT_EQ(std::string(to_string(s.status)), "stopped_by_callback");
    if (spec.rfind("nlopt", 0) != 0) {  // NLopt returns its best point, not the last evaluated
      EXPECT_LE((x - last).lpNorm<Eigen::Infinity>(), 1e-15) << spec;
    }
  }
}

// A stop at a point whose residual shows a solution: usable, as a run cut short there is.
TEST(IterationCallback, AStopAtASolutionIsUsable) {
  for (const std::string& spec : kOwnLoopEngines) {
    SolverOptions o;
    o.stop.step_tolerance = 1e-14;  // would run on past the callback's point
    o.iteration_callback = [](const IterationRecord& r) {
      return r.residual_norm <= 1e-9 ? IterationDecision::kStop : IterationDecision::kContinue;
    };
    auto engine = EngineRegistry<Dynamic>::global().create(spec, o);
    Vector<> x = start();
    const Summary s = engine->solve(coupled_cosine(), x);
    // (The step tolerance, 1e-14, is met well after |F| <= 1e-9: every engine is stopped.)
    EXPECT_EQ(s.status, Status::kStoppedByCallback) << spec << '\n' << s.full_report();
    EXPECT_TRUE(s.usable()) << spec << ": " << s.unusable_reason();
  }
}

TEST(IterationCallback, AnExceptionItThrowsLeavesSolveUnchanged) {
  struct Cancelled : std::runtime_error {
    Cancelled() : std::runtime_error("cancelled by the user") {}
  };
  std::vector<std::string> specs = kOwnLoopEngines;
  specs.insert(specs.end(), {"ceres", "nlopt:LN_BOBYQA"});
  for (const std::string& spec : specs) {
    bool cancel = true;
    SolverOptions o = tight();
    o.iteration_callback = [&cancel](const IterationRecord&) {
      if (cancel) throw Cancelled();
      return IterationDecision::kContinue;
    };
    auto engine = EngineRegistry<Dynamic>::global().create(spec, o);
    Vector<> x = start();
    EXPECT_THROW(engine->solve(coupled_cosine(), x), Cancelled) << spec;
    // The same engine solves again afterwards (Ceres and NLopt keep prepared state across solves).
    cancel = false;
    Vector<> y = start();
    EXPECT_TRUE(engine->solve(coupled_cosine(), y).usable()) << spec;
  }
}

// auto: each stage has the callback; a stop ends the run, no later stage runs.
TEST(IterationCallback, AStopEndsAutoWithoutTheLaterStages) {
  int calls = 0;
  SolverOptions o = tight();
  o.iteration_callback = [&calls](const IterationRecord&) {
    ++calls;
    return IterationDecision::kStop;
  };
  auto engine = EngineRegistry<Dynamic>::global().create("auto:order=newton/dogleg", o);
  Vector<> x = start();
  const Summary s = engine->solve(coupled_cosine(), x);
  EXPECT_EQ(s.status, Status::kStoppedByCallback) << s.full_report();
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(s.stage, "newton");
}

// The answer of a stopped auto is where the callback stopped it, with that stage's summary, even
// when an earlier stage left a smaller residual.
TEST(IterationCallback, AStoppedAutoReturnsTheStoppedStagesIterate) {
  SolverOptions one_step = tight();
  one_step.stop.max_iterations = 1;  // newton ends max_iterations: not usable, but close
  Eigen::VectorXd seen;
  SolverOptions stopping = tight();
  stopping.iteration_callback = [&seen](const IterationRecord& r) {
    seen = r.x;
    return IterationDecision::kStop;
  };
  std::vector<std::unique_ptr<Engine<>>> stages;
  stages.push_back(std::make_unique<NewtonEngine<>>(NewtonOptions{}, one_step));
  stages.push_back(std::make_unique<PicardEngine<>>(stopping));
  PolyalgorithmEngine<> engine(std::move(stages), PolyalgorithmOptions{}, tight());
  Vector<> x = start();
  const Summary s = engine.solve(coupled_cosine(), x);
  EXPECT_EQ(s.status, Status::kStoppedByCallback) << s.full_report();
  EXPECT_EQ(s.stage, "picard");
  ASSERT_EQ(seen.size(), 2);
  EXPECT_EQ(x, seen);
}

// At n = 100 000 on the sparse path (a chain nlobs does not ship, F_i = x_i + x_i^3/10 - 1 +
// (x_{i-1} + x_{i+1})/5, its pattern detected): the record is the iterate itself, not a copy,
// and a stop leaves x where the callback saw it.
TEST(IterationCallback, ALargeSparseSolveReportsAndStops) {
  const Index n = 100000;
  const auto chain = [n](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    Eigen::Matrix<T, Eigen::Dynamic, 1> f(n);
    for (Index i = 0; i < n; ++i) {
      const T left = i > 0 ? T(x[i - 1]) : T(0.0), right = i + 1 < n ? T(x[i + 1]) : T(0.0);
      f[i] = x[i] + 0.1 * x[i] * x[i] * x[i] - 1.0 + 0.2 * (left + right);
    }
    return f;
  };
  const FixedPointProblem<> problem = to_fixed_point(RootProblem<>::with_autodiff(chain, n, n));
  std::vector<double> residuals;
  const double* first_data = nullptr;
  Eigen::VectorXd seen;
  SolverOptions o = tight();
  o.iteration_callback = [&](const IterationRecord& r) {
    residuals.push_back(r.residual_norm);
    if (first_data == nullptr) first_data = r.x.data();
    EXPECT_EQ(r.x.data(), first_data);  // the engine's own iterate each time: no copy
    if (residuals.size() < 2) return IterationDecision::kContinue;
    seen = r.x;
    return IterationDecision::kStop;
  };
  auto engine = EngineRegistry<Dynamic>::global().create("newton:line_search=1", o);
  Vector<> x = Vector<>::Zero(n);
  const Summary s = engine->solve(problem, x);
  EXPECT_EQ(s.status, Status::kStoppedByCallback) << s.full_report();
  EXPECT_FALSE(s.linear_solver.empty()) << "the sparse path";
  ASSERT_EQ(residuals.size(), 2U);
  EXPECT_LT(residuals[1], residuals[0]);
  ASSERT_EQ(seen.size(), n);
  EXPECT_EQ(x, seen);

  // Run on, the same solve converges; the callback saw every iteration.
  SolverOptions quiet = tight();
  int calls = 0;
  quiet.iteration_callback = [&calls](const IterationRecord&) {
    ++calls;
    return IterationDecision::kContinue;
  };
  auto on = EngineRegistry<Dynamic>::global().create("newton:line_search=1", quiet);
  on->set_record_trace(true);  // switched on after construction, at n = 10^5
  x.setZero();
  const Summary done = on->solve(problem, x);
  EXPECT_EQ(done.status, Status::kConverged) << done.full_report();
  EXPECT_EQ(calls, done.iterations);
  ASSERT_EQ(static_cast<int>(done.trace.size()), done.iterations);
  for (const TraceEntry& t : done.trace) EXPECT_EQ(t.x.size(), n);
  EXPECT_EQ(done.trace.back().x, x);
}

// Ceres: TinySolver has no callback; auto takes the Solver back end when one is set.
TEST(IterationCallback, CeresTakesTheSolverBackEndForACallback) {
  SolverOptions o = tight();
  int calls = 0;
  o.iteration_callback = [&calls](const IterationRecord&) {
    ++calls;
    return IterationDecision::kContinue;
  };
  EXPECT_THROW(CeresEngine<2>(CeresOptions{.backend = CeresOptions::Backend::kTinySolver}, o),
               InvalidInput);
  CeresEngine<2> engine(CeresOptions{}, o);
  EXPECT_FALSE(engine.uses_tiny_solver());
  EXPECT_TRUE(CeresEngine<2>(CeresOptions{}, tight()).uses_tiny_solver());
  Vector<2> x(1.0, -1.0);
  const FixedPointProblem<2> problem = coupled_cosine_fixed();
  const Summary s = engine.solve(problem, x);
  EXPECT_TRUE(s.usable()) << s.full_report();
  EXPECT_GE(calls, 2);  // Ceres' iteration 0 and at least one step
}

}  // namespace
}  // namespace nlobs
