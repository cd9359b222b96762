// Engines by name: every built-in round-trips, options reach the engine, errors list the
// valid names and options, users register their own engines.
#include <gtest/gtest.h>

#include "nlobs/solvers/engine_registry.hpp"
#include "test_support.hpp"

namespace nlobs {
namespace {

using test::message_of;

TEST(EngineSpec, Parses) {
  const EngineSpec s = parse_engine_spec("nlopt:LN_BOBYQA,xtol_rel=1e-6");
  EXPECT_EQ(s.name, "nlopt");
  ASSERT_EQ(s.words.size(), 1U);
  EXPECT_EQ(s.words[0], "LN_BOBYQA");
  ASSERT_EQ(s.values.size(), 1U);
  EXPECT_EQ(s.values[0].first, "xtol_rel");
  EXPECT_EQ(s.values[0].second, "1e-6");
  EXPECT_NE(message_of([] { parse_engine_spec(":m=3"); }).find("no engine name"),
            std::string::npos);
  EXPECT_NE(message_of([] { parse_engine_spec("anderson:m=3,,x"); }).find("empty item"),
            std::string::npos);
  EXPECT_NE(message_of([] { parse_engine_spec("anderson:m=3,m=4"); }).find("'m' twice"),
            std::string::npos);
  EXPECT_NE(message_of([] { parse_engine_spec("anderson:m="); }).find("key=value"),
            std::string::npos);
}

TEST(EngineRegistry, EveryBuiltInRoundTrips) {
  auto& registry = EngineRegistry<1>::global();
  const std::vector<std::string> expected = {"aitken", "anderson", "ceres",     "newton",
                                             "nlopt",  "picard",   "steffensen"};
  std::vector<std::string> names = registry.names();
  for (const std::string& e : expected) {
    EXPECT_NE(std::find(names.begin(), names.end(), e), names.end()) << e;
  }
  SolverOptions o;
  o.stop.step_tolerance = 1e-10;
  o.stop.residual_tolerance = 1e-10;
  for (const auto& entry : registry.entries()) {
    for (const std::string& spec : entry.examples) {
      auto engine = registry.create(spec, o);
      ASSERT_TRUE(engine) << spec;
      EXPECT_EQ(engine->name(), entry.name) << spec;  // the spec names the engine it builds
      Vector<1> x(1.0);
      const Summary s = engine->solve(test::cosine_problem(), x);
      EXPECT_NEAR(x[0], test::kDottie, 1e-4) << spec << '\n' << s.full_report();
    }
  }
}

TEST(EngineRegistry, OptionsReachTheEngine) {
  auto& registry = EngineRegistry<2>::global();
  auto anderson = registry.create("anderson:m=5,damping=0.25,tol=1e-3,max_iter=7");
  auto* a = dynamic_cast<AndersonEngine<2>*>(anderson.get());
  ASSERT_NE(a, nullptr);
  EXPECT_EQ(a->accelerator().options().depth, 5);
  EXPECT_EQ(a->accelerator().options().damping, 0.25);
  EXPECT_EQ(*a->options().stop.step_tolerance, 1e-3);
  EXPECT_EQ(a->options().stop.max_iterations, 7);

  auto newton = registry.create("newton:linesearch=1,fd=forward,ftol=1e-9,max_evals=50");
  auto* n = dynamic_cast<NewtonEngine<2>*>(newton.get());
  ASSERT_NE(n, nullptr);
  EXPECT_TRUE(n->newton_options().line_search);
  EXPECT_EQ(n->newton_options().finite_difference, FiniteDifference::kForward);
  EXPECT_EQ(*n->options().stop.residual_tolerance, 1e-9);
  EXPECT_EQ(n->options().stop.max_evaluations, 50);

  auto ceres = registry.create("ceres:dogleg,backend=solver,jacobi=1,nonmonotonic=0");
  auto* c = dynamic_cast<CeresEngine<2>*>(ceres.get());
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(c->ceres_options().method, CeresOptions::Method::kDogleg);
  EXPECT_EQ(c->ceres_options().backend, CeresOptions::Backend::kSolver);
  EXPECT_TRUE(c->ceres_options().jacobi_scaling);
  EXPECT_FALSE(c->ceres_options().nonmonotonic_steps);

  auto nlopt = registry.create("nlopt:LD_SLSQP,xtol_rel=1e-6");
  auto* l = dynamic_cast<NloptEngine<2>*>(nlopt.get());
  ASSERT_NE(l, nullptr);
  EXPECT_EQ(l->nlopt_options().algorithm, "LD_SLSQP");
  EXPECT_EQ(l->nlopt_options().relative_step_tolerance, 1e-6);
}

TEST(EngineRegistry, ErrorsListWhatIsValid) {
  auto& registry = EngineRegistry<1>::global();
  const std::string unknown = message_of([&] { registry.create("bogus"); });
  EXPECT_NE(unknown.find("unknown engine 'bogus'"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("steffensen"), std::string::npos) << unknown;
  const std::string option = message_of([&] { registry.create("anderson:depth=3"); });
  EXPECT_NE(option.find("unknown option(s) depth"), std::string::npos) << option;
  EXPECT_NE(option.find("damping"), std::string::npos) << option;  // lists valid options
  EXPECT_NE(
      message_of([&] { registry.create("anderson:m=abc"); }).find("'m=abc' is not an integer"),
      std::string::npos);
  EXPECT_NE(message_of([&] { registry.create("anderson:m=-2"); }).find("depth = -2"),
            std::string::npos);
  EXPECT_NE(message_of([&] { registry.create("ceres:trust"); }).find("'trust' is not one of"),
            std::string::npos);
  EXPECT_NE(message_of([&] { registry.create("picard:tol=0"); }).find("step_tolerance = 0"),
            std::string::npos);
  EXPECT_NE(message_of([&] { registry.create("newton:linesearch=maybe"); }).find("not 0/1"),
            std::string::npos);
  EXPECT_NE(message_of([&] { registry.create("steffensen:fast"); }).find("unknown option(s) fast"),
            std::string::npos);
}

// A user's engine: damped Picard, registered under its own name.
class HalfStep : public Engine<1> {
 public:
  explicit HalfStep(double weight, SolverOptions o) : Engine<1>(o), engine_(o), weight_(weight) {}
  std::string_view name() const override { return "halfstep"; }
  Summary solve(const FixedPointProblem<1>& p, Vector<1>& x) override {
    const auto relaxed =
        FixedPointProblem<1>::from_map([&p, this](const Vector<1>& v, Vector<1>& g) {
          p.evaluate(v, g);
          g = v + weight_ * (g - v);
        });
    return engine_.solve(relaxed, x);
  }

 private:
  PicardEngine<1> engine_;
  double weight_;
};

TEST(EngineRegistry, UsersRegisterTheirOwn) {
  auto& registry = EngineRegistry<1>::global();
  if (!registry.contains("halfstep")) {
    registry.add({"halfstep",
                  "Picard relaxed by a weight",
                  {{"w", "weight; default 0.5"}},
                  {"halfstep:w=0.6"},
                  [](EngineSpecReader& s, SolverOptions o) {
                    return std::make_unique<HalfStep>(s.number("w").value_or(0.5), o);
                  }});
  }
  auto engine = registry.create("halfstep:w=0.6,tol=1e-12");
  EXPECT_EQ(engine->name(), "halfstep");
  Vector<1> x(1.0);
  EXPECT_TRUE(engine->solve(test::cosine_problem(), x).converged());
  EXPECT_NEAR(x[0], test::kDottie, 1e-10);
  EXPECT_NE(message_of([&] {
              registry.add({"halfstep", "", {}, {}, nullptr});
            }).find("already registered"),
            std::string::npos);
  EXPECT_THROW(registry.add({"bad:name", "", {}, {}, nullptr}), InvalidInput);
  EXPECT_NE(message_of([&] {
              registry.add({"nofactory", "", {}, {}, nullptr});
            }).find("has no factory"),
            std::string::npos);
  EXPECT_FALSE(registry.contains("nofactory"));
}

}  // namespace
}  // namespace nlobs
