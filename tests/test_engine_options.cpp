// Each engine owns its options: Options::validate() (called by the engine's constructor) refuses
// every field out of range or not finite with one message shape, Options::read() sets only what
// a spec gives, and engine_entry() registers an engine of that shape, a user's as a built-in.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "nlobs/solvers/builtin_engines.hpp"
#include "nlobs/solvers/options_validation.hpp"
#include "test_support.hpp"

namespace nlobs {
namespace {

using test::message_of;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(EngineOptions, DefaultsAreValid) {
  EXPECT_NO_THROW(NewtonOptions{}.validate());
  EXPECT_NO_THROW(DoglegOptions{}.validate());
  EXPECT_NO_THROW(BroydenOptions{}.validate());
  EXPECT_NO_THROW(LevenbergMarquardtOptions{}.validate());
  EXPECT_NO_THROW(PseudoTransientOptions{}.validate());
  EXPECT_NO_THROW(PolyalgorithmOptions{}.validate());
  EXPECT_NO_THROW(AndersonOptions{}.validate());
  EXPECT_NO_THROW(CeresOptions{}.validate());
  EXPECT_NO_THROW(NloptOptions{}.validate());
}

// One bad field each: the message names the options type, the field and the value; NaN and
// infinities are refused wherever a number must be finite or lie in a range.
TEST(EngineOptions, EachBadFieldIsRefusedByTypeFieldAndValue) {
  struct Case {
    std::function<void()> validate;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {[] { NewtonOptions{.sufficient_decrease = kNaN}.validate(); },
       "NewtonOptions::sufficient_decrease = nan is invalid"},
      {[] { NewtonOptions{.backtrack_factor = 1.0}.validate(); },
       "NewtonOptions::backtrack_factor = 1 is invalid: must lie in (0, 1)"},
      {[] { NewtonOptions{.max_backtracks = 0}.validate(); },
       "NewtonOptions::max_backtracks = 0 is invalid"},
      {[] { NewtonOptions{.jacobian_reuse = 1001}.validate(); },
       "NewtonOptions::jacobian_reuse = 1001 is invalid"},
      {[] { NewtonOptions{.linear_solver = "cholesky"}.validate(); },
       "NewtonOptions::linear_solver"},
      {[] { DoglegOptions{.initial_radius_factor = kInf}.validate(); },
       "DoglegOptions::initial_radius_factor = inf is invalid"},
      {[] { BroydenOptions{.max_backtracks = 61}.validate(); },
       "BroydenOptions::max_backtracks = 61 is invalid"},
      {[] { BroydenOptions{.memory = 0}.validate(); }, "BroydenOptions::memory = 0 is invalid"},
      {[] { BroydenOptions{.linear_solver = "gmres"}.validate(); },
       "must be applied exactly, by a direct solver"},
      {[] { LevenbergMarquardtOptions{.function_tolerance = -1e-3}.validate(); },
       "LevenbergMarquardtOptions::function_tolerance = -0.001 is invalid"},
      {[] { LevenbergMarquardtOptions{.second_derivative_step = kNaN}.validate(); },
       "LevenbergMarquardtOptions::second_derivative_step = nan is invalid"},
      {[] { LevenbergMarquardtOptions{.linear_solver = "klu"}.validate(); },
       "must be auto, dense or cholmod"},
      {[] { PseudoTransientOptions{.initial_pseudo_step = 1e-17}.validate(); },
       "PseudoTransientOptions::initial_pseudo_step (delta0) = 1e-17 is invalid"},
      {[] { PseudoTransientOptions{.max_pseudo_step = kInf}.validate(); },
       "PseudoTransientOptions::max_pseudo_step (delta_max) = inf is invalid"},
      {[] { PseudoTransientOptions{.pseudo_step_growth = 11.0}.validate(); },
       "PseudoTransientOptions::pseudo_step_growth (growth) = 11 is invalid"},
      {[] { PseudoTransientOptions{.linear_tolerance = 1.0}.validate(); },
       "PseudoTransientOptions::linear_tolerance = 1 is invalid"},
      {[] { PolyalgorithmOptions{.shared_minimum = -1}.validate(); },
       "PolyalgorithmOptions::shared_minimum = -1 is invalid"},
      {[] { PolyalgorithmOptions{.dense_stage_limit = -5}.validate(); },
       "PolyalgorithmOptions::dense_stage_limit = -5 is invalid"},
      {[] { BroydenOptions{.max_updates = -2000000}.validate(); },
       "BroydenOptions::max_updates = -2000000 is invalid"},  // integers written exactly
      {[] { NewtonOptions{.forcing = {.maximum = 1.5}}.validate(); },
       "ForcingTermOptions::maximum = 1.5"},
      {[] { AndersonOptions{.depth = -1}.validate(); },
       "AndersonOptions::depth = -1 is invalid: must be in 0..1000"},
      {[] { AndersonOptions{.damping = kNaN}.validate(); },
       "AndersonOptions::damping = nan is invalid"},
      {[] { AndersonOptions{.condition_limit = 1.0}.validate(); },
       "AndersonOptions::condition_limit = 1 is invalid"},
      {[] { CeresOptions{.gradient_tolerance = kNaN}.validate(); },
       "CeresOptions::gradient_tolerance = nan is invalid"},
      {[] {
         CeresOptions{.method = CeresOptions::Method::kDogleg,
                      .backend = CeresOptions::Backend::kTinySolver}
             .validate();
       },
       "kTinySolver is Levenberg-Marquardt only"},
      {[] { NloptOptions{.algorithm = ""}.validate(); }, "NloptOptions::algorithm = ''"},
      {[] { NloptOptions{.algorithm = "LN_NOPE"}.validate(); }, "is not an NLopt algorithm"},
      {[] { NloptOptions{.algorithm = "GN_DIRECT_L"}.validate(); },
       "global algorithm GN_DIRECT_L needs finite lower_bounds and upper_bounds"},
      {[] { NloptOptions{.relative_step_tolerance = kNaN}.validate(); },
       "NloptOptions::relative_step_tolerance = nan is invalid"},
      {[] { NloptOptions{.initial_step = 0.0}.validate(); },
       "NloptOptions::initial_step = 0 is invalid"},
  };
  for (const Case& c : cases) {
    const std::string message = message_of(c.validate);
    EXPECT_TRUE(contains(message, c.expected))
        << "expected: " << c.expected << "\ngot: " << message;
  }
}

// The constructor calls validate(): no engine holds options it refuses.
TEST(EngineOptions, EnginesRefuseWhatTheirOptionsRefuse) {
  EXPECT_THROW(NewtonEngine<>(NewtonOptions{.backtrack_factor = kNaN}), InvalidInput);
  EXPECT_THROW(NewtonEngine<>(NewtonOptions{.line_search = true, .trust_region = true}),
               InvalidInput);
  EXPECT_THROW(DoglegEngine<2>(DoglegOptions{.initial_radius_factor = 0.0}), InvalidInput);
  EXPECT_THROW(BroydenEngine<>(BroydenOptions{.sufficient_decrease = 0.5}), InvalidInput);
  EXPECT_THROW(LevenbergMarquardtEngine<>(LevenbergMarquardtOptions{.acceleration_ratio = -1.0}),
               InvalidInput);
  EXPECT_THROW(PseudoTransientEngine<>(PseudoTransientOptions{.min_pseudo_step = 1.0}),
               InvalidInput);
  EXPECT_THROW(AndersonEngine<>(AndersonOptions{.damping = 0.0}), InvalidInput);
  EXPECT_THROW(NloptEngine<>(NloptOptions{.algorithm = "LN_NOPE"}), InvalidInput);
  EXPECT_THROW(CeresEngine<>(CeresOptions{.function_tolerance = -1.0}), InvalidInput);
  // What depends on the size stays with the engine.
  EXPECT_TRUE(contains(message_of([] { AndersonEngine<2>(AndersonOptions{.depth = 17}); }),
                       "AndersonOptions::depth = 17 is invalid: must be in 0..16 for fixed sizes"));
  EXPECT_TRUE(contains(message_of([] { AndersonEngine<2>(AndersonOptions{.depth = -1}); }),
                       "AndersonOptions::depth = -1 is invalid: must be in 0..16 for fixed sizes"));
  EXPECT_NO_THROW(AndersonEngine<>(AndersonOptions{.depth = 17}));
  EXPECT_TRUE(contains(message_of([] {
                         CeresEngine<>(CeresOptions{.backend = CeresOptions::Backend::kTinySolver});
                       }),
                       "kTinySolver needs a compile-time size"));
}

// read() sets the fields the spec gives, over whatever the options held; the rest stay.
TEST(EngineOptions, ReadSetsOnlyWhatTheSpecGives) {
  NewtonOptions newton{.linear_solver = "klu", .jacobian_reuse = 5};
  const EngineSpec spec = parse_engine_spec("newton:line_search=1,fd=forward");
  EngineSpecReader reader(spec, NewtonOptions::describe().options);
  newton.read(reader);
  EXPECT_NO_THROW(reader.finish());
  EXPECT_TRUE(newton.line_search);
  EXPECT_EQ(newton.finite_difference, FiniteDifference::kForward);
  EXPECT_EQ(newton.jacobian_reuse, 5);
  EXPECT_EQ(newton.linear_solver, "klu");

  // A δ₀ below δ_min takes δ_min down with it, and the result validates.
  PseudoTransientOptions ptc;
  const EngineSpec small = parse_engine_spec("pseudo-transient:delta0=1e-14");
  EngineSpecReader small_reader(small, PseudoTransientOptions::describe().options);
  ptc.read(small_reader);
  EXPECT_EQ(ptc.initial_pseudo_step, 1e-14);
  EXPECT_EQ(ptc.min_pseudo_step, 1e-14);
  EXPECT_NO_THROW(ptc.validate());

  // A value the reader accepts (a finite number) but the options refuse is refused by
  // validate(), named; the reader itself refuses what is not a finite number.
  const std::string refused =
      message_of([] { EngineRegistry<Dynamic>::global().create("levenberg-marquardt:gtol=-1"); });
  EXPECT_TRUE(contains(refused, "LevenbergMarquardtOptions::gradient_tolerance = -1 is invalid"))
      << refused;
  const std::string not_finite =
      message_of([] { EngineRegistry<Dynamic>::global().create("levenberg-marquardt:gtol=nan"); });
  EXPECT_TRUE(contains(not_finite, "'gtol=nan' is not a finite number")) << not_finite;
}

// The spec keys are the field names, the older names their aliases: the table of
// docs/solvers.md, written out here so that a key renamed or an alias dropped fails; and the
// engine each description names is the one the registry builds under that name.
TEST(EngineOptions, EveryBuiltInHasTheDocumentedKeysAndAliases) {
  using Keys = std::vector<std::pair<std::string, std::vector<std::string>>>;
  const std::vector<std::pair<EngineDescription, Keys>> documented = {
      {PicardEngine<>::describe(), {}},
      {AitkenEngine<>::describe(), {}},
      {SteffensenEngine<>::describe(), {}},
      {AndersonOptions::describe(),
       {{"depth", {"m"}}, {"damping", {}}, {"condition_limit", {"cond"}}}},
      {NewtonOptions::describe(),
       {{"line_search", {"linesearch"}},
        {"trust_region", {"trustregion"}},
        {"finite_difference", {"fd"}},
        {"linear_solver", {"linear"}},
        {"preconditioner", {}},
        {"ordering", {}},
        {"jacobian_reuse", {"reuse"}}}},
      {DoglegOptions::describe(),
       {{"scaling", {"scale"}},
        {"initial_radius_factor", {"factor"}},
        {"broyden_updates", {"broyden"}},
        {"finite_difference", {"fd"}}}},
      {BroydenOptions::describe(),
       {{"max_backtracks", {"backtracks"}},
        {"max_updates", {"updates"}},
        {"finite_difference", {"fd"}},
        {"linear_solver", {"linear"}},
        {"ordering", {}},
        {"memory", {}}}},
      {LevenbergMarquardtOptions::describe(),
       {{"scaling", {"scale"}},
        {"initial_radius_factor", {"factor"}},
        {"geodesic_acceleration", {"geodesic"}},
        {"function_tolerance", {"ftol"}},
        {"gradient_tolerance", {"gtol"}},
        {"finite_difference", {"fd"}},
        {"linear_solver", {"linear"}}}},
      {PseudoTransientOptions::describe(),
       {{"flow", {}},
        {"initial_pseudo_step", {"delta0"}},
        {"max_pseudo_step", {"delta_max"}},
        {"pseudo_step_growth", {"growth"}},
        {"finite_difference", {"fd"}},
        {"linear_solver", {"linear"}},
        {"preconditioner", {}},
        {"ordering", {}}}},
      {PolyalgorithmOptions::describe(),
       {{"order", {}},
        {"from", {}},
        {"shared_minimum", {}},
        {"dense_stage_limit", {"dense_limit"}}}},
      {CeresOptions::describe(),
       {{"<lm|dogleg>", {}},
        {"backend", {}},
        {"function_tolerance", {"function_tol"}},
        {"gradient_tolerance", {"gradient_tol"}},
        {"jacobi_scaling", {"jacobi"}},
        {"nonmonotonic_steps", {"nonmonotonic"}}}},
      {NloptOptions::describe(),
       {{"<ALGORITHM>", {}}, {"relative_step_tolerance", {"xtol_rel"}}, {"initial_step", {}}}},
  };
  auto& registry = EngineRegistry<Dynamic>::global();
  for (const std::string& name : registry.names()) {  // every built-in has its row here
    if (registry.source(name) != "built-in") continue;
    EXPECT_TRUE(std::any_of(documented.begin(), documented.end(), [&name](const auto& row) {
      return row.first.name == name;
    })) << name;
  }
  for (const auto& [description, keys] : documented) {
    SCOPED_TRACE(description.name);
    ASSERT_EQ(description.options.size(), keys.size());
    for (std::size_t i = 0; i < keys.size(); ++i) {
      EXPECT_EQ(description.options[i].key, keys[i].first);
      EXPECT_EQ(description.options[i].aliases, keys[i].second);
    }
    EXPECT_EQ(registry.create(description.name)->name(), description.name);
    for (const std::string& example : description.examples) {
      EXPECT_NO_THROW(registry.create(example)) << example;
    }
  }
}

// A user's engine in the built-ins' shape (an engine nlobs does not ship: Picard with a damping
// factor), registered by one line and reached by name with its own option.
struct DampedPicardOptions {
  double damping = 1.0;  // ω in x ← (1 − ω) x + ω G(x), ω ∈ (0, 1]
  void validate() const {
    require_option(damping > 0.0 && damping <= 1.0, "DampedPicardOptions", "damping", damping,
                   "must lie in (0, 1]");
  }
  static EngineDescription describe() {
    return {"test-damped-picard",
            "x <- (1 - w) x + w G(x)",
            {{"damping", "w in (0, 1]; default 1", {"w"}}},
            {"test-damped-picard:damping=0.5"}};
  }
  void read(EngineSpecReader& spec) {
    if (auto v = spec.number("damping")) damping = *v;
  }
};

class DampedPicardEngine : public Engine<> {
 public:
  using Options = DampedPicardOptions;
  explicit DampedPicardEngine(DampedPicardOptions damped = {}, SolverOptions options = {})
      : Engine<>(std::move(options)), damped_(damped) {
    damped_.validate();
  }
  std::string_view name() const override { return "test-damped-picard"; }
  Summary solve(const FixedPointProblem<>& problem, Vector<>& x) override {
    Summary summary;
    summary.engine = name();
    Vector<> g(x.size());
    for (int k = 0; k < options().stop.max_iterations; ++k) {
      problem.evaluate(x, g);
      ++summary.function_evaluations;
      ++summary.iterations;
      const Vector<> next = (1.0 - damped_.damping) * x + damped_.damping * g;
      summary.residual_norm = (g - x).lpNorm<Eigen::Infinity>();
      const double step = (next - x).lpNorm<Eigen::Infinity>();
      x = next;
      if (step <= 1e-12) {
        summary.status = Status::kConverged;
        break;
      }
    }
    if (summary.status != Status::kConverged) summary.status = Status::kMaxIterations;
    summary.record_answer(x, options().stop);
    return summary;
  }

 private:
  DampedPicardOptions damped_;
};

TEST(EngineOptions, AUserEngineOfTheSameShapeRegistersInOneLine) {
  auto& registry = EngineRegistry<Dynamic>::global();
  if (!registry.has_entry("test-damped-picard")) {
    registry.add(engine_entry<Dynamic, DampedPicardEngine>(), "tests/test_engine_options.cpp");
  }
  const auto cosine = FixedPointProblem<>::with_autodiff(
      [](const auto& x, auto& g) {
        using std::cos;
        g[0] = cos(x[0]);
      },
      1);
  auto engine = registry.create("test-damped-picard:w=0.7");
  Vector<> x = Vector<>::Constant(1, 1.0);
  const Summary s = engine->solve(cosine, x);
  EXPECT_EQ(s.status, Status::kConverged);
  EXPECT_NEAR(x[0], test::kDottie, 1e-10);
  EXPECT_TRUE(contains(message_of([&] { registry.create("test-damped-picard:damping=2"); }),
                       "DampedPicardOptions::damping = 2 is invalid: must lie in (0, 1]"));
  EXPECT_TRUE(contains(message_of([&] { registry.create("test-damped-picard:omega=2"); }),
                       "unknown option(s) 'omega'"));
  // At a fixed size it comes through the Dynamic entry, as every user engine does.
  auto two = EngineRegistry<2>::global().create("test-damped-picard:damping=0.5");
  EXPECT_EQ(two->name(), "test-damped-picard");
}

// NLopt's box through set_bounds: one the algorithm refuses leaves the engine as it was.
TEST(EngineOptions, ARefusedBoxLeavesTheNloptOptionsAsTheyWere) {
  const Eigen::VectorXd lower = Eigen::VectorXd::Constant(2, -1.0),
                        upper = Eigen::VectorXd::Constant(2, 1.0);
  NloptEngine<> engine(
      NloptOptions{.algorithm = "GN_DIRECT_L", .lower_bounds = lower, .upper_bounds = upper});
  EXPECT_THROW(engine.set_bounds(BoxBounds{Eigen::VectorXd::Constant(2, -kInf), upper}),
               InvalidInput);
  EXPECT_EQ(engine.nlopt_options().lower_bounds, lower);
  EXPECT_EQ(engine.bounds().lower, lower);
}

}  // namespace
}  // namespace nlobs
