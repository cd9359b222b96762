// Engines by name: every built-in round-trips, options reach the engine, errors list the
// valid names and options, users register their own engines, and one registration at Dynamic
// serves every size (library sizes and others).
#include <gtest/gtest.h>

#include "nlobs/solvers/builtin_engines.hpp"
#include "nlobs/solvers/ceres_engine.hpp"
#include "nlobs/solvers/engine_registry.hpp"
#include "nlobs/solvers/fixed_point_engines.hpp"
#include "nlobs/solvers/levenberg_marquardt_engine.hpp"
#include "nlobs/solvers/newton_engine.hpp"
#include "nlobs/solvers/nlopt_engine.hpp"
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
  const std::vector<std::string> expected = {
      "aitken", "anderson", "auto",   "broyden",          "ceres",      "dogleg",
      "newton", "nlopt",    "picard", "pseudo-transient", "steffensen", "levenberg-marquardt"};
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

TEST(EngineRegistry, KeysAreFieldNamesWithTheOldNamesAsAliases) {
  auto& registry = EngineRegistry<2>::global();
  for (const char* spec :
       {"anderson:depth=5,condition_limit=1e6,step_tolerance=1e-3,max_iterations=7",
        "anderson:m=5,cond=1e6,tol=1e-3,max_iter=7"}) {
    auto engine = registry.create(spec);
    auto* a = dynamic_cast<AndersonEngine<2>*>(engine.get());
    ASSERT_NE(a, nullptr) << spec;
    EXPECT_EQ(a->accelerator().options().depth, 5) << spec;
    EXPECT_EQ(a->accelerator().options().condition_limit, 1e6) << spec;
    EXPECT_EQ(*a->options().stop.step_tolerance, 1e-3) << spec;
    EXPECT_EQ(a->options().stop.max_iterations, 7) << spec;
  }
  for (const char* spec : {"newton:line_search=1,finite_difference=forward,jacobian_reuse=3,"
                           "residual_tolerance=1e-9,max_evaluations=50",
                           "newton:linesearch=1,fd=forward,reuse=3,ftol=1e-9,max_evals=50"}) {
    auto engine = registry.create(spec);
    auto* n = dynamic_cast<NewtonEngine<2>*>(engine.get());
    ASSERT_NE(n, nullptr) << spec;
    EXPECT_TRUE(n->newton_options().line_search) << spec;
    EXPECT_EQ(n->newton_options().finite_difference, FiniteDifference::kForward) << spec;
    EXPECT_EQ(n->newton_options().jacobian_reuse, 3) << spec;
    EXPECT_EQ(*n->options().stop.residual_tolerance, 1e-9) << spec;
    EXPECT_EQ(n->options().stop.max_evaluations, 50) << spec;
  }
  // A key and its alias in one spec: refused, naming both.
  const std::string both = message_of([&] { registry.create("anderson:m=3,depth=4"); });
  EXPECT_NE(both.find("'m' and 'depth' name the same option 'depth': give one"), std::string::npos)
      << both;
  EXPECT_THROW(registry.create("picard:tol=1e-3,step_tolerance=1e-4"), InvalidInput);

  // levenberg-marquardt's own ftol (MINPACK's) no longer sets the common residual tolerance too.
  auto lm = registry.create("levenberg-marquardt:ftol=1e-3");
  auto* l = dynamic_cast<LevenbergMarquardtEngine<2>*>(lm.get());
  ASSERT_NE(l, nullptr);
  EXPECT_EQ(l->lm_options().function_tolerance, 1e-3);
  EXPECT_FALSE(l->options().stop.residual_tolerance.has_value());
  lm = registry.create("levenberg-marquardt:residual_tolerance=1e-6,function_tolerance=1e-4");
  l = dynamic_cast<LevenbergMarquardtEngine<2>*>(lm.get());
  ASSERT_NE(l, nullptr);
  EXPECT_EQ(l->lm_options().function_tolerance, 1e-4);
  EXPECT_EQ(*l->options().stop.residual_tolerance, 1e-6);
  EXPECT_THROW(registry.create("levenberg-marquardt:ftol=1e-3,function_tolerance=1e-4"),
               InvalidInput);
  // Where ftol is not the engine's own, it is still the residual tolerance.
  auto newton = registry.create("newton:ftol=1e-7");
  EXPECT_EQ(*newton->options().stop.residual_tolerance, 1e-7);

  // A user's engine declaring a common key itself: the key is its own there, aliases included.
  auto& dynamic = EngineRegistry<Dynamic>::global();
  if (!dynamic.has_entry("own-iterations")) {
    dynamic.add({"own-iterations",
                 "Picard counting its own iterations",
                 {{"max_iterations", "the engine's own", {"max_iter"}}},
                 {"own-iterations"},
                 [](EngineSpecReader& s, SolverOptions o) -> std::unique_ptr<Engine<>> {
                   if (auto v = s.integer("max_iterations", 1, 100)) o.stop.max_iterations = 2 * *v;
                   return std::make_unique<PicardEngine<>>(std::move(o));
                 }},
                "tests/test_registry.cpp");
  }
  EXPECT_EQ(dynamic.create("own-iterations:max_iter=5")->options().stop.max_iterations, 10);
  EXPECT_THROW(dynamic.create("own-iterations:max_iterations=500"), InvalidInput);  // its range
  // A registration that declares one name twice is refused when the engine is made, named.
  if (!dynamic.has_entry("twice-named")) {
    dynamic.add({"twice-named",
                 "declares m as an alias of two options",
                 {{"depth", "a", {"m"}}, {"memory", "b", {"m"}}},
                 {"twice-named"},
                 [](EngineSpecReader&, SolverOptions o) -> std::unique_ptr<Engine<>> {
                   return std::make_unique<PicardEngine<>>(std::move(o));
                 }},
                "tests/test_registry.cpp");
  }
  EXPECT_NE(message_of([&] { dynamic.create("twice-named"); }).find("'m' twice"),
            std::string::npos);
}

TEST(EngineRegistry, ErrorsListWhatIsValid) {
  auto& registry = EngineRegistry<1>::global();
  const std::string unknown = message_of([&] { registry.create("bogus"); });
  EXPECT_NE(unknown.find("unknown engine 'bogus'"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("steffensen"), std::string::npos) << unknown;
  const std::string option = message_of([&] { registry.create("anderson:size=3"); });
  EXPECT_NE(option.find("unknown option(s) 'size'"), std::string::npos) << option;
  EXPECT_NE(option.find("damping"), std::string::npos) << option;       // lists valid options
  EXPECT_NE(option.find("depth or m ("), std::string::npos) << option;  // and their aliases
  EXPECT_NE(
      message_of([&] { registry.create("anderson:m=abc"); }).find("'m=abc' is not an integer"),
      std::string::npos);
  EXPECT_NE(message_of([&] {
              registry.create("anderson:m=-2");
            }).find("'m=-2' is out of range: must be in 0.."),
            std::string::npos);
  // The library's own check stands behind the spec's (a user building AndersonMixing directly).
  EXPECT_NE(message_of([] {
              AndersonMixing<Dynamic>(AndersonOptions{.depth = 5000});
            }).find("depth = 5000 is invalid: must be in 0..1000"),
            std::string::npos);
  EXPECT_NE(message_of([&] { registry.create("ceres:trust"); }).find("'trust' is not one of"),
            std::string::npos);
  EXPECT_NE(message_of([&] { registry.create("picard:tol=0"); }).find("step_tolerance = 0"),
            std::string::npos);
  EXPECT_NE(message_of([&] { registry.create("newton:linesearch=maybe"); }).find("not 0/1"),
            std::string::npos);
  EXPECT_NE(
      message_of([&] { registry.create("steffensen:fast"); }).find("unknown option(s) 'fast'"),
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

// A user's engine, generic in the size: x ← x + w (G(x) − x), written once.
template <int N>
class Relaxed final : public Engine<N> {
 public:
  Relaxed(double w, SolverOptions o) : Engine<N>(std::move(o)), w_(w) {}
  std::string_view name() const override { return "relaxed"; }
  Summary solve(const FixedPointProblem<N>& problem, Vector<N>& x) override {
    detail::check_initial_guess(name(), problem, x);
    Summary s;
    s.engine = name();
    Vector<N> g = x;
    for (; s.iterations < this->options_.stop.max_iterations; ++s.iterations) {
      problem.evaluate(x, g);
      ++s.function_evaluations;
      const double step = w_ * (g - x).template lpNorm<Eigen::Infinity>();
      x += w_ * (g - x);
      if (!(step > *this->options_.stop.step_tolerance)) {
        s.status = Status::kConverged;
        s.residual_norm = step / w_;
        return s;
      }
    }
    s.status = Status::kMaxIterations;
    return s;
  }

 private:
  double w_;
};

// G_i(x) = 0.5 cos(x_i) + 0.1 i: a contraction in any dimension n.
template <int N>
FixedPointProblem<N> cosine_chain(Index n = N) {
  return FixedPointProblem<N>::with_autodiff(
      [n](const auto& x) {
        using T = typename std::decay_t<decltype(x)>::Scalar;
        Eigen::Matrix<T, N, 1> g(n);
        for (Index i = 0; i < n; ++i) g[i] = 0.5 * cos(x[i]) + 0.1 * static_cast<double>(i);
        return g;
      },
      n);
}

template <int N>
double fixed_point_residual(const Vector<N>& x) {
  double r = 0.0;
  for (Index i = 0; i < x.size(); ++i) {
    r = std::max(r, std::abs(0.5 * std::cos(x[i]) + 0.1 * static_cast<double>(i) - x[i]));
  }
  return r;
}

template <int N>
void expect_relaxed_solves(Index n = N) {
  auto engine = EngineRegistry<N>::global().create("relaxed:w=0.8,tol=1e-13");
  ASSERT_TRUE(engine);
  EXPECT_EQ(engine->name(), "relaxed");
  Vector<N> x = Vector<N>::Zero(n);
  const Summary s = engine->solve(cosine_chain<N>(n), x);
  EXPECT_TRUE(s.converged()) << N << '\n' << s.full_report();
  EXPECT_LT(fixed_point_residual<N>(x), 1e-12) << N;
}

TEST(EngineRegistry, OneRegistrationAtDynamicServesEverySize) {
  auto& dynamic = EngineRegistry<Dynamic>::global();
  if (!dynamic.contains("relaxed")) {
    dynamic.add({"relaxed",
                 "relaxed Picard",
                 {{"w", "weight in (0, 1]; default 0.5"}},
                 {"relaxed:w=0.8"},
                 [](EngineSpecReader& s, SolverOptions o) -> std::unique_ptr<Engine<Dynamic>> {
                   return std::make_unique<Relaxed<Dynamic>>(s.number("w").value_or(0.5),
                                                             std::move(o));
                 }});
  }
  expect_relaxed_solves<Dynamic>(6);
  expect_relaxed_solves<1>();  // library sizes
  expect_relaxed_solves<3>();
  expect_relaxed_solves<5>();  // sizes the library does not compile
  expect_relaxed_solves<7>();
  EXPECT_TRUE(EngineRegistry<7>::global().contains("relaxed"));
  const auto names = EngineRegistry<7>::global().names();
  EXPECT_NE(std::find(names.begin(), names.end(), "relaxed"), names.end());
  // Its options are checked as at Dynamic.
  EXPECT_NE(message_of([] {
              EngineRegistry<5>::global().create("relaxed:q=1");
            }).find("unknown option(s) 'q'"),
            std::string::npos);
}

TEST(EngineRegistry, AFixedSizeEntryShadowsTheDynamicOne) {
  auto& dynamic = EngineRegistry<Dynamic>::global();
  if (!dynamic.contains("shadowed")) {
    dynamic.add({"shadowed", "at Dynamic", {}, {}, [](EngineSpecReader&, SolverOptions o) {
                   return std::make_unique<Relaxed<Dynamic>>(0.5, std::move(o));
                 }});
  }
  auto& fixed = EngineRegistry<6>::global();
  try {
    fixed.add({"shadowed", "at 6", {}, {}, [](EngineSpecReader&, SolverOptions o) {
                 return std::make_unique<Relaxed<6>>(0.5, std::move(o));
               }});
  } catch (const InvalidInput& e) {  // a repeated test: added the first time
    EXPECT_NE(std::string(e.what()).find("already registered"), std::string::npos);
  }
  auto engine = fixed.create("shadowed");
  EXPECT_NE(dynamic_cast<Relaxed<6>*>(engine.get()), nullptr);
  EXPECT_TRUE(fixed.has_entry("shadowed"));
  EXPECT_FALSE(fixed.has_entry("relaxed"));  // served from Dynamic, not its own
  int listed = 0;
  for (const auto& e : fixed.entries()) {
    if (e.name == "shadowed") {
      ++listed;
      EXPECT_EQ(e.description, "at 6");
    }
  }
  EXPECT_EQ(listed, 1);
  // At another fixed size the Dynamic entry still serves, adapted.
  auto other = EngineRegistry<5>::global().create("shadowed");
  EXPECT_NE(dynamic_cast<DynamicSizeEngine<5>*>(other.get()), nullptr);
}

TEST(EngineRegistry, BuiltInsAtSizesTheLibraryDoesNotCompile) {
  static_assert(!is_library_size(5) && is_library_size(3) && is_library_size(Dynamic));
  SolverOptions o;
  o.stop.step_tolerance = 1e-12;
  o.stop.residual_tolerance = 1e-12;
  // Through the Dynamic entries: every built-in solves a 5-dimensional problem.
  for (const char* spec : {"picard", "aitken", "steffensen", "anderson", "newton", "ceres",
                           "nlopt:LN_BOBYQA,xtol_rel=1e-14"}) {
    auto engine = EngineRegistry<5>::global().create(spec, o);
    ASSERT_NE(dynamic_cast<DynamicSizeEngine<5>*>(engine.get()), nullptr) << spec;
    Vector<5> x = Vector<5>::Zero();
    const Summary s = engine->solve(cosine_chain<5>(), x);
    EXPECT_LT(fixed_point_residual<5>(x), 1e-6) << spec << '\n' << s.full_report();
  }
  // Newton sees the problem's AD Jacobian through the adapter: no differencing.
  auto newton = EngineRegistry<5>::global().create("newton", o);
  Vector<5> x = Vector<5>::Zero();
  const Summary s = newton->solve(cosine_chain<5>(), x);
  EXPECT_TRUE(s.converged());
  EXPECT_GT(s.jacobian_evaluations, 0);
  EXPECT_LE(s.function_evaluations, s.iterations + 2) << s.full_report();
  // Without a Jacobian Newton differences G through the adapter.
  const auto plain = FixedPointProblem<5>::from_map([](const Vector<5>& v, Vector<5>& g) {
    for (Index i = 0; i < 5; ++i) g[i] = 0.5 * std::cos(v[i]) + 0.1 * static_cast<double>(i);
  });
  Vector<5> xp = Vector<5>::Zero();
  const Summary sp = newton->solve(plain, xp);
  EXPECT_TRUE(sp.converged()) << sp.full_report();
  EXPECT_GT(sp.function_evaluations, s.function_evaluations);  // the differences count
  EXPECT_LT(fixed_point_residual<5>(xp), 1e-10);
  // The fixed-size-only Ceres back end names the way out at a size without its own entries.
  EXPECT_NE(message_of([] {
              EngineRegistry<5>::global().create("ceres:backend=tiny");
            }).find("add_builtin_engines<5>"),
            std::string::npos);
  // Least squares (m = 7 > n = 5) through the adapter: F_i = x_{i mod 5} − c_{i mod 5}.
  const Vector<5> c(1.0, -2.0, 3.0, 0.5, 4.0);
  const auto f = [c](const Vector<5>& v, Vector<Dynamic>& r) {
    r.resize(7);
    for (Index i = 0; i < 7; ++i) r[i] = v[i % 5] - c[i % 5];
  };
  auto ceres = EngineRegistry<5>::global().create("ceres", o);
  EXPECT_TRUE(ceres->least_squares());
  Vector<5> y = Vector<5>::Zero();
  const Summary ls = ceres->solve_least_squares(RootProblem<5, Dynamic>::from_map(f, 5, 7), y);
  EXPECT_TRUE(ls.converged()) << ls.full_report();
  EXPECT_LT((y - c).lpNorm<Eigen::Infinity>(), 1e-8);
  // With its Jacobian (counted, no differencing): the same answer.
  int jacobians = 0;
  const auto df = [&jacobians](const Vector<5>&, Matrix<Dynamic, 5>& j) {
    ++jacobians;
    j.setZero(7, 5);
    for (Index i = 0; i < 7; ++i) j(i, i % 5) = 1.0;
  };
  Vector<5> yj = Vector<5>::Zero();
  const Summary lsj =
      ceres->solve_least_squares(RootProblem<5, Dynamic>::with_jacobian(f, df, 5, 7), yj);
  EXPECT_TRUE(lsj.converged()) << lsj.full_report();
  EXPECT_GT(jacobians, 0);
  EXPECT_LT((yj - c).lpNorm<Eigen::Infinity>(), 1e-8);
  // Fixed-size built-ins at another size on request (builtin_engines.hpp): no adapter. The
  // registry is process-wide, so a repeated test finds them there already.
  auto& eight = EngineRegistry<8>::global();
  if (!eight.has_entry("newton")) {  // first in this process: the Dynamic engine, adapted
    EXPECT_NE(dynamic_cast<DynamicSizeEngine<8>*>(eight.create("newton").get()), nullptr);
  }
  add_builtin_engines<8>(eight);
  add_builtin_engines<8>(eight);  // idempotent
  auto fixed_newton = eight.create("newton", o);
  ASSERT_NE(dynamic_cast<NewtonEngine<8>*>(fixed_newton.get()), nullptr);
  Vector<8> z = Vector<8>::Zero();
  EXPECT_TRUE(fixed_newton->solve(cosine_chain<8>(), z).converged());
  EXPECT_LT(fixed_point_residual<8>(z), 1e-12);
}

TEST(EngineRegistry, FactoriesThatReturnNothingAreNamed) {
  auto& registry = EngineRegistry<Dynamic>::global();
  if (!registry.contains("nothing")) {
    registry.add({"nothing", "", {}, {}, [](EngineSpecReader&, SolverOptions) {
                    return std::unique_ptr<Engine<Dynamic>>();
                  }});
  }
  EXPECT_NE(message_of([&] { registry.create("nothing"); }).find("returned no engine"),
            std::string::npos);
  EXPECT_NE(
      message_of([] { EngineRegistry<5>::global().create("nothing"); }).find("returned no engine"),
      std::string::npos);
  EXPECT_NE(message_of([] { DynamicSizeEngine<2> e(nullptr); }).find("null"), std::string::npos);
}

// User text in messages: quoted, control characters visible, cut (never inside a UTF-8
// character), so a hostile megabyte-long spec gives a one-line error.
TEST(QuotedExcerpt, ShortVisibleAndWholeCharacters) {
  EXPECT_EQ(quoted_excerpt("m=3"), "'m=3'");
  EXPECT_EQ(quoted_excerpt(std::string("a\nb\0c", 5)), "'a\\x0ab\\x00c'");
  EXPECT_EQ(quoted_excerpt(std::string(100, 'x')), "'" + std::string(60, 'x') + "...'");
  // "é" is two bytes; a cut after the first would leave half a character.
  EXPECT_EQ(quoted_excerpt("abcdé", 5), "'abcd...'");
  EXPECT_EQ(quoted_excerpt("abcdé", 6), "'abcdé'");
  auto& registry = EngineRegistry<1>::global();
  const std::string e =
      message_of([&] { registry.create("anderson:" + std::string(100000, 'q') + "=1"); });
  EXPECT_LT(e.size(), 1500U) << e.size();
  EXPECT_NE(e.find("unknown option(s) 'qqq"), std::string::npos) << e.substr(0, 300);
}

}  // namespace
}  // namespace nlobs
