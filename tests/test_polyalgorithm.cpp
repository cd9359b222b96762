// The polyalgorithm (`auto`): switching engines when the first fails, one shared budget, the best
// point when all fail, the registry's spec. (The default order against MINPACK's published
// runs: tests/test_minpack_reference.cpp.)
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "nlobs/solvers/builtin_engines.hpp"
#include "test_support.hpp"

namespace nlobs {
namespace {

SolverOptions strict() {
  SolverOptions o = test::tolerance(1e-13);
  o.stop.residual_tolerance = 1e-12;
  return o;
}

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
  // No root: every stage fails; together they never exceed the budget.
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
  EXPECT_NE(s.message.find("dogleg"), std::string::npos) << s.message;
}

TEST(Polyalgorithm, RestartsFromTheBestPointOrFromTheStart) {
  // Stage 1 (picard on G = x + F, with F = x² − 4) diverges from 1.5 after a few steps; from
  // the best point so far and from the start the dogleg then finds the root +2.
  for (const bool best : {true, false}) {
    auto engine = poly({"picard", "dogleg"}, {.restart_from_best = best});
    Eigen::VectorXd x = Eigen::VectorXd::Constant(1, 1.5);
    const Summary s = engine->solve(parabola(-4.0), x);
    ASSERT_TRUE(s.converged()) << s.full_report();
    EXPECT_EQ(s.stage, "dogleg");
    EXPECT_NEAR(std::abs(x[0]), 2.0, 1e-12);
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
  // A fixed size gets fixed-size stages.
  EXPECT_EQ(EngineRegistry<3>::global().create("auto")->name(), "auto");
}

}  // namespace
}  // namespace nlobs
