// The polyalgorithm (`auto`): switching engines when the first fails, one shared budget, the best
// point when all fail, the registry's spec. (The default order against MINPACK's published
// runs: tests/test_minpack_reference.cpp.)
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>

#include "nlobs/solvers/builtin_engines.hpp"
#include "nlobs/solvers/dynamic_size_engine.hpp"
#include "test_support.hpp"

namespace nlobs {
namespace {

using test::strict;

// F(x) = x² + c.
FixedPointProblem<> parabola(double c) {
  return to_fixed_point(RootProblem<>::with_autodiff(
      [c](const auto& x) {
        using T = typename std::decay_t<decltype(x)>::Scalar;
        Eigen::Matrix<T, Eigen::Dynamic, 1> f(1);
        f[0] = x[0] * x[0] + c;
        return f;
      },
      1, 1));
}

// A user's stage: records where it started, moves x to `to` in one evaluation and stops as
// `status`; optionally throws, ignores its limit (reports `spend` evaluations) or skips
// record_answer.
class ScriptedEngine : public Engine<> {
 public:
  struct Script {
    Eigen::VectorXd to;
    Status status = Status::kStagnated;
    bool throws = false;
    int spend = 1;
    bool record = true;
  };
  ScriptedEngine(Script script, Eigen::VectorXd* started_at)
      : Engine<>(SolverOptions{}), script_(std::move(script)), started_at_(started_at) {}
  std::string_view name() const override { return "scripted"; }
  Summary solve(const FixedPointProblem<>& problem, Eigen::VectorXd& x) override {
    if (started_at_) *started_at_ = x;
    if (script_.throws) throw std::runtime_error("scripted failure");
    x = script_.to;
    Eigen::VectorXd g(x.size());
    problem.evaluate(x, g);
    Summary s;
    s.engine = name();
    s.status = script_.status;
    s.function_evaluations = script_.spend;
    s.residual_norm = (g - x).lpNorm<Eigen::Infinity>();
    if (script_.record) s.record_answer(x, options().stop);
    return s;
  }

 private:
  Script script_;
  Eigen::VectorXd* started_at_;
};

std::unique_ptr<PolyalgorithmEngine<>> poly(const std::vector<std::string>& names,
                                            PolyalgorithmOptions p = {},
                                            SolverOptions o = strict()) {
  std::vector<std::unique_ptr<Engine<>>> stages;
  for (const auto& n : names) stages.push_back(EngineRegistry<>::global().create(n, o));
  return std::make_unique<PolyalgorithmEngine<>>(std::move(stages), p, o);
}

TEST(Polyalgorithm, SwitchesWhenTheFirstEngineFails) {
  // x² − 1 from 0: Newton's Jacobian is singular there; the dogleg's is regularised.
  auto engine = poly({"newton", "dogleg"});
  Eigen::VectorXd x = Eigen::VectorXd::Zero(1);
  const Summary s = engine->solve(parabola(-1.0), x);
  ASSERT_TRUE(s.converged()) << s.full_report();
  EXPECT_NEAR(std::abs(x[0]), 1.0, 1e-12);
  EXPECT_EQ(s.engine, "auto");
  EXPECT_EQ(s.stage, "dogleg");
  EXPECT_NE(s.message.find("newton singular_jacobian"), std::string::npos) << s.message;
  // Newton's one evaluation counts too.
  Eigen::VectorXd y = Eigen::VectorXd::Zero(1);
  const Summary alone = DoglegEngine<>({}, strict()).solve(parabola(-1.0), y);
  EXPECT_EQ(s.function_evaluations, alone.function_evaluations + 1);
  EXPECT_NE(s.brief_report().find("auto (dogleg)"), std::string::npos) << s.brief_report();
}

TEST(Polyalgorithm, OneBudgetForAllStages) {
  // No root: every stage fails; together they never exceed the budget, and each one ran.
  SolverOptions o = strict();
  o.stop.max_evaluations = 40;
  auto engine = poly({"dogleg", "levenberg-marquardt", "pseudo-transient"}, {}, o);
  Eigen::VectorXd x = Eigen::VectorXd::Constant(1, 3.0);
  const Summary s = engine->solve(parabola(1.0), x);
  EXPECT_FALSE(s.usable());
  EXPECT_LE(s.function_evaluations, 40) << s.full_report();
  // The best point any stage found: close to the minimiser 0 of ‖F‖, with its residual.
  EXPECT_LT(std::abs(x[0]), 0.1);
  EXPECT_NEAR(s.residual_norm, x[0] * x[0] + 1.0, 1e-12);
  for (const char* stage : {"dogleg", "levenberg-marquardt"}) {
    EXPECT_NE(s.message.find(stage), std::string::npos) << s.message;
  }
  // newton:trustregion=1 runs an inner dogleg built with its own (large) budget: auto's limit
  // reaches it too. From 30 it needs more than 5 evaluations to reach the root 1.
  SolverOptions small = strict();
  small.stop.max_evaluations = 5;
  std::vector<std::unique_ptr<Engine<>>> stages;
  stages.push_back(EngineRegistry<>::global().create("newton:trustregion=1", strict()));
  PolyalgorithmEngine<> nested(std::move(stages), {}, small);
  x.setConstant(30.0);
  const Summary n = nested.solve(parabola(-1.0), x);
  EXPECT_LE(n.function_evaluations, 5) << n.full_report();
  EXPECT_FALSE(n.usable());
}

TEST(Polyalgorithm, RestartsFromTheBestPointOrFromTheStart) {
  // Stage 1 moves x from 3 to 0.5 (|F| from 8 to 0.75 for F = x² − 1) and gives up; stage 2
  // starts at 0.5 with restart_from_best, at 3 without.
  for (const bool best : {true, false}) {
    Eigen::VectorXd first_start, second_start;
    std::vector<std::unique_ptr<Engine<>>> stages;
    stages.push_back(std::make_unique<ScriptedEngine>(
        ScriptedEngine::Script{.to = Eigen::VectorXd::Constant(1, 0.5)}, &first_start));
    stages.push_back(std::make_unique<ScriptedEngine>(
        ScriptedEngine::Script{.to = Eigen::VectorXd::Constant(1, 1.0),
                               .status = Status::kConverged},
        &second_start));
    PolyalgorithmEngine<> engine(std::move(stages), {.restart_from_best = best}, strict());
    Eigen::VectorXd x = Eigen::VectorXd::Constant(1, 3.0);
    const Summary s = engine.solve(parabola(-1.0), x);
    ASSERT_TRUE(s.usable()) << s.full_report();
    EXPECT_EQ(first_start[0], 3.0);
    EXPECT_EQ(second_start[0], best ? 0.5 : 3.0);
    EXPECT_EQ(x[0], 1.0);
  }
}

// Stages scripted to end at `ends` (x, status), in order, on F = x² − 1 from 3.
Summary run_scripted(const std::vector<std::pair<double, Status>>& ends, Eigen::VectorXd& x) {
  std::vector<std::unique_ptr<Engine<>>> stages;
  for (const auto& [to, status] : ends) {
    stages.push_back(std::make_unique<ScriptedEngine>(
        ScriptedEngine::Script{.to = Eigen::VectorXd::Constant(1, to), .status = status}, nullptr));
  }
  PolyalgorithmEngine<> engine(std::move(stages), {}, strict());
  x = Eigen::VectorXd::Constant(1, 3.0);
  return engine.solve(parabola(-1.0), x);
}

TEST(Polyalgorithm, ASharedMinimumNamesOnlyItsOwnPoint) {
  Eigen::VectorXd x;
  // Stage 1 ends singular near the root (|F| 5e-7, within acceptance_tolerance); stages 2 and 3
  // meet at x = 0 (|F| = 1). The answer is stage 1's point with stage 1's status: unusable, not
  // a local minimum made usable by its small |F|.
  const double near_root = 1.0 + 2.5e-7;
  Summary s = run_scripted({{near_root, Status::kSingularJacobian},
                            {0.0, Status::kStagnated},
                            {0.0, Status::kStagnated},
                            {1.0, Status::kConverged}},
                           x);
  EXPECT_EQ(x[0], near_root);
  EXPECT_EQ(s.status, Status::kSingularJacobian) << s.message;
  EXPECT_FALSE(s.usable());
  EXPECT_NE(s.message.find("a local minimum of |F| that is not a root"), std::string::npos)
      << s.message;  // the history still says why the run stopped

  // Where the meeting point is the best, it is a local minimum, whatever held one stage ...
  s = run_scripted({{0.0, Status::kBlockedByBound}, {0.0, Status::kStagnated}}, x);
  EXPECT_EQ(x[0], 0.0);
  EXPECT_EQ(s.status, Status::kLocalMinimum) << s.message;
  s = run_scripted({{0.0, Status::kStagnated}, {0.0, Status::kBlockedByBound}}, x);
  EXPECT_EQ(s.status, Status::kLocalMinimum) << s.message;
  s = run_scripted({{0.0, Status::kStagnated}, {1e-4, Status::kBlockedByBound}}, x);
  EXPECT_EQ(s.status, Status::kLocalMinimum) << s.message;  // the best is the blocked one's
  // ... and blocked by a bound when a bound held every stage that met there.
  s = run_scripted({{2.0, Status::kStagnated},
                    {0.0, Status::kBlockedByBound},
                    {0.0, Status::kBlockedByBound},
                    {1.0, Status::kConverged}},
                   x);
  EXPECT_EQ(x[0], 0.0);
  EXPECT_EQ(s.status, Status::kBlockedByBound) << s.message;
  EXPECT_NE(s.message.find("not run: scripted"), std::string::npos) << s.message;
}

TEST(Polyalgorithm, UsersStagesThatThrowSkipRecordingOrOverrunTheirLimit) {
  Eigen::VectorXd ignored;
  const Eigen::VectorXd root = Eigen::VectorXd::Constant(1, 1.0);
  {  // a throwing stage is a line of the history; the next stage answers
    std::vector<std::unique_ptr<Engine<>>> stages;
    stages.push_back(std::make_unique<ScriptedEngine>(
        ScriptedEngine::Script{.to = root, .throws = true}, &ignored));
    stages.push_back(EngineRegistry<>::global().create("dogleg", strict()));
    PolyalgorithmEngine<> engine(std::move(stages), {}, strict());
    Eigen::VectorXd x = Eigen::VectorXd::Constant(1, 3.0);
    const Summary s = engine.solve(parabola(-1.0), x);
    EXPECT_TRUE(s.converged()) << s.full_report();
    EXPECT_EQ(s.stage, "dogleg");
    EXPECT_NE(s.message.find("scripted threw: scripted failure"), std::string::npos) << s.message;
  }
  {  // a converged answer without record_answer is still an answer: no further stage runs
    Eigen::VectorXd second_start;
    std::vector<std::unique_ptr<Engine<>>> stages;
    stages.push_back(std::make_unique<ScriptedEngine>(
        ScriptedEngine::Script{.to = root, .status = Status::kConverged, .record = false},
        &ignored));
    stages.push_back(
        std::make_unique<ScriptedEngine>(ScriptedEngine::Script{.to = root}, &second_start));
    PolyalgorithmEngine<> engine(std::move(stages), {}, strict());
    Eigen::VectorXd x = Eigen::VectorXd::Constant(1, 3.0);
    const Summary s = engine.solve(parabola(-1.0), x);
    EXPECT_TRUE(s.usable()) << s.full_report();
    EXPECT_EQ(second_start.size(), 0);
  }
  {  // a stage that overruns its limit ends the run; the overrun is reported, not hidden
    SolverOptions o = strict();
    o.stop.max_evaluations = 10;
    Eigen::VectorXd second_start;
    std::vector<std::unique_ptr<Engine<>>> stages;
    stages.push_back(std::make_unique<ScriptedEngine>(
        ScriptedEngine::Script{.to = Eigen::VectorXd::Constant(1, 2.0), .spend = 25}, &ignored));
    stages.push_back(
        std::make_unique<ScriptedEngine>(ScriptedEngine::Script{.to = root}, &second_start));
    PolyalgorithmEngine<> engine(std::move(stages), {}, o);
    Eigen::VectorXd x = Eigen::VectorXd::Constant(1, 3.0);
    const Summary s = engine.solve(parabola(-1.0), x);
    EXPECT_FALSE(s.usable());
    EXPECT_EQ(s.function_evaluations, 25);
    EXPECT_EQ(second_start.size(), 0);
    EXPECT_EQ(s.status, Status::kStagnated);  // its own status, never turned into a usable one
    EXPECT_NE(s.message.find("budget (10) is spent"), std::string::npos) << s.message;
  }
}

TEST(Polyalgorithm, SpecsAndBadInput) {
  auto& registry = EngineRegistry<>::global();
  const auto a = registry.create("auto");
  EXPECT_EQ(a->name(), "auto");
  const auto* stages = dynamic_cast<const PolyalgorithmEngine<>*>(a.get());
  ASSERT_NE(stages, nullptr);
  ASSERT_EQ(stages->stages().size(), 4u);
  EXPECT_EQ(stages->stages()[0]->name(), "newton");
  EXPECT_EQ(stages->stages()[3]->name(), "pseudo-transient");
  EXPECT_EQ(registry.create("auto:order=newton/dogleg,from=start")->name(), "auto");
  EXPECT_NE(test::message_of([&] { registry.create("auto:order=auto/dogleg"); }).find("other"),
            std::string::npos);
  EXPECT_NE(
      test::message_of([&] { registry.create("auto:order=newton//dogleg"); }).find("separated"),
      std::string::npos);
  EXPECT_NE(test::message_of([&] { registry.create("auto:order=newton/nope"); }).find("nope"),
            std::string::npos);
  EXPECT_NE(test::message_of([&] { registry.create("auto:from=middle"); }).find("from"),
            std::string::npos);
  EXPECT_NE(test::message_of([] {
              PolyalgorithmEngine<>(std::vector<std::unique_ptr<Engine<>>>{});
            }).find("at least one"),
            std::string::npos);
  // A fixed size gets fixed-size stages, not the Dynamic ones adapted.
  const auto fixed = EngineRegistry<3>::global().create("auto");
  const auto* poly3 = dynamic_cast<const PolyalgorithmEngine<3>*>(fixed.get());
  ASSERT_NE(poly3, nullptr);
  for (const auto& stage : poly3->stages()) {
    EXPECT_EQ(dynamic_cast<const DynamicSizeEngine<3>*>(stage.get()), nullptr) << stage->name();
  }
  EXPECT_NE(
      test::message_of([&] { registry.create("auto:order=auto:from=best/dogleg"); }).find("other"),
      std::string::npos);
}

}  // namespace
}  // namespace nlobs
