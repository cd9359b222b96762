// Problem sets nlobs does not ship: a user's two-problem set (a root problem with bounds and a
// known solution, a fixed point) registered as the built-ins are, run by the suite with a user's
// engine beside KINSOL and MINPACK, judged alike; every malformed problem refused naming it; the
// CLI's table, JSON and CSV of such a set.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <new>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "nlobs/reference/problem_suite.hpp"
#include "nlobs/registry/problem_sets.hpp"
#include "nlobs/solvers/engine_registry.hpp"
#include "nlobs/solvers/fixed_point_engines.hpp"
#include "suite_command.hpp"
#include "suite_report.hpp"

namespace nlobs {
namespace {

using reference::SuiteOptions;
using reference::SuiteRow;

// The circle x1² + x2² = 4 meets the line x1 = x2 at ±(√2, √2); the box [0, 3]² keeps one.
TestProblem circle_and_line() {
  TestProblem p =
      root_test_problem("circle-line", 2,
                        [](const auto& x, auto& f) {
                          f[0] = x[0] * x[0] + x[1] * x[1] - 4.0;
                          f[1] = x[0] - x[1];
                        },
                        {{"near", Eigen::Vector2d(1.0, 2.0)}, {"far", Eigen::Vector2d(3.0, 0.1)}});
  p.lower = Eigen::Vector2d(0.0, 0.0);
  p.upper = Eigen::Vector2d(3.0, 3.0);
  p.solutions = {Eigen::Vector2d(std::sqrt(2.0), std::sqrt(2.0))};
  return p;
}

// x = cos x (Dottie's number), three unknowns at once.
TestProblem cosine_fixed_point() {
  return fixed_point_test_problem("cosine", 3,
                                  [](const auto& x, auto& g) {
                                    using std::cos;
                                    for (int i = 0; i < 3; ++i) g[i] = cos(x[i]);
                                  },
                                  {{"zero", Eigen::Vector3d::Zero()}});
}

// Throws from F at one point: the suite must turn it into a row, whichever solver meets it.
TestProblem hostile() {
  return root_test_problem("hostile", 1,
                           [](const auto& x, auto& f) {
                             if (x[0] > 0.5) throw std::runtime_error("the model left its domain");
                             f[0] = x[0] - 1.0;
                           },
                           {{"x0", Eigen::VectorXd::Constant(1, 0.0)}});
}

// An engine a user registered: it throws while solving.
class ThrowingEngine final : public Engine<Dynamic> {
 public:
  explicit ThrowingEngine(SolverOptions o) : Engine<Dynamic>(std::move(o)) {}
  std::string_view name() const override { return "test-throws"; }
  Summary solve(const FixedPointProblem<Dynamic>&, Vector<Dynamic>&) override {
    throw std::runtime_error("a user's engine failed");
  }
};

// An engine a user registered: throws something that is not a std::exception.
class ThrowsFortyTwo final : public Engine<Dynamic> {
 public:
  explicit ThrowsFortyTwo(SolverOptions o) : Engine<Dynamic>(std::move(o)) {}
  std::string_view name() const override { return "test-throws-42"; }
  Summary solve(const FixedPointProblem<Dynamic>&, Vector<Dynamic>&) override { throw 42; }
};

// An engine a user registered that ignores its budget: evaluates G a thousand times, then
// returns the root it was told about (x = 1 for the problems it meets here).
class GreedyEngine final : public Engine<Dynamic> {
 public:
  explicit GreedyEngine(SolverOptions o) : Engine<Dynamic>(std::move(o)) {}
  std::string_view name() const override { return "test-greedy"; }
  Summary solve(const FixedPointProblem<Dynamic>& g, Vector<Dynamic>& x) override {
    Vector<Dynamic> out(x.size());
    for (int i = 0; i < 1000; ++i) g.evaluate(x, out);
    x.setOnes();
    Summary s;
    s.engine = "test-greedy";
    s.status = Status::kConverged;
    s.function_evaluations = 1;  // and it under-reports
    return s;
  }
};

// An engine a user registered that counts its solves and returns at once.
class CountingEngine final : public Engine<Dynamic> {
 public:
  static inline int solves = 0;
  explicit CountingEngine(SolverOptions o) : Engine<Dynamic>(std::move(o)) {}
  std::string_view name() const override { return "test-counts"; }
  Summary solve(const FixedPointProblem<Dynamic>&, Vector<Dynamic>&) override {
    ++solves;
    Summary s;
    s.engine = "test-counts";
    s.status = Status::kMaxIterations;
    return s;
  }
};

void register_once() {
  static const bool done = [] {
    problem_set_registry().add(
        ProblemSetEntry{
            .name = "test-set",
            .description = "a test's two problems",
            .problems =
                [] {
                  return std::vector<TestProblem>{circle_and_line(), cosine_fixed_point()};
                }},
        "test_problem_sets");
    problem_set_registry().add(
        ProblemSetEntry{.name = "test-hostile",
                        .description = "F throws",
                        .problems = [] { return std::vector<TestProblem>{hostile()}; }},
        "test_problem_sets");
    auto& engines = EngineRegistry<Dynamic>::global();
    engines.add({"test-picard",
                 "Picard under a user's name",
                 {},
                 {"test-picard"},
                 [](EngineSpecReader&, SolverOptions o) -> std::unique_ptr<Engine<Dynamic>> {
                   return std::make_unique<PicardEngine<Dynamic>>(o);
                 }});
    engines.add({"test-throws-42",
                 "throws 42",
                 {},
                 {"test-throws-42"},
                 [](EngineSpecReader&, SolverOptions o) -> std::unique_ptr<Engine<Dynamic>> {
                   return std::make_unique<ThrowsFortyTwo>(o);
                 }});
    engines.add({"test-greedy",
                 "ignores its budget",
                 {},
                 {"test-greedy"},
                 [](EngineSpecReader&, SolverOptions o) -> std::unique_ptr<Engine<Dynamic>> {
                   return std::make_unique<GreedyEngine>(o);
                 }});
    engines.add({"test-counts",
                 "counts its solves",
                 {},
                 {"test-counts"},
                 [](EngineSpecReader&, SolverOptions o) -> std::unique_ptr<Engine<Dynamic>> {
                   return std::make_unique<CountingEngine>(o);
                 }});
    engines.add({"test-throws",
                 "throws",
                 {},
                 {"test-throws"},
                 [](EngineSpecReader&, SolverOptions o) -> std::unique_ptr<Engine<Dynamic>> {
                   return std::make_unique<ThrowingEngine>(o);
                 }});
    return true;
  }();
  (void)done;
}

const SuiteRow& row(const std::vector<SuiteRow>& rows, const std::string& problem,
                    const std::string& start, const std::string& solver) {
  for (const SuiteRow& r : rows) {
    if (r.problem == problem && r.start == start && r.solver == solver) return r;
  }
  throw std::logic_error("no row " + problem + " " + start + " " + solver);
}

TEST(ProblemSets, AUsersSetRunsEverySolverOnEveryStartJudgedAlike) {
  register_once();
  const ProblemSelection s = select_problems("test-set", problem_set_registry());
  ASSERT_EQ(s.problems.size(), 2u);
  const std::vector<std::string> solvers = {"newton", "test-picard", "kinsol:newton",
                                            "minpack:hybrj", "kinsol:fp"};
  const auto rows = reference::run_suite(*s.set, s.problems, solvers);
  ASSERT_EQ(rows.size(), (2u + 1u) * solvers.size());
  for (const SuiteRow& r : rows) {
    SCOPED_TRACE(r.problem + " " + r.start + " " + r.solver);
    EXPECT_EQ(r.set, "test-set");
    EXPECT_EQ(r.solved, r.residual <= 1e-8 && r.status != "outside_bounds");
  }
  // Newton, KINSOL and MINPACK find (√2, √2) from the near start, inside the box.
  for (const char* solver : {"newton", "kinsol:newton", "minpack:hybrj"}) {
    const SuiteRow& r = row(rows, "circle-line", "near", solver);
    EXPECT_TRUE(r.solved) << solver << " " << r.status;
    EXPECT_LT(r.error, 1e-8) << solver;
  }
  // The fixed point: Picard iterates G = cos (a contraction), KINSOL's fixed point too.
  for (const char* solver : {"test-picard", "kinsol:fp", "newton"}) {
    const SuiteRow& r = row(rows, "cosine", "zero", solver);
    EXPECT_TRUE(r.solved) << solver << " " << r.status;
    EXPECT_TRUE(std::isnan(r.error));  // no known solution listed
  }
  // Picard on x + F (the circle problem has no contraction): not solved, said so.
  EXPECT_FALSE(row(rows, "circle-line", "near", "test-picard").solved);
}

TEST(ProblemSets, APointOutsideTheBoundsIsNotASolution) {
  register_once();
  // x² = 1 in [-0.9, 2] from -0.5: MINPACK (unbounded) goes to -1, a root outside the box;
  // newton gets the box and stops on its bound, where its step points out.
  TestProblem p =
      root_test_problem("square", 1, [](const auto& x, auto& f) { f[0] = x[0] * x[0] - 1.0; },
                        {{"left", Eigen::VectorXd::Constant(1, -0.5)}});
  p.lower = Eigen::VectorXd::Constant(1, -0.9);
  p.upper = Eigen::VectorXd::Constant(1, 2.0);
  const ProblemSetEntry set{.name = "one", .problems = [p] { return std::vector<TestProblem>{p}; }};
  const auto rows = reference::run_suite(set, build_problem_set(set), {"minpack:hybrj", "newton"});
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].status, "outside_bounds");
  EXPECT_FALSE(rows[0].solved);
  EXPECT_LT(rows[0].residual, 1e-8);  // a root, but not in the box
  EXPECT_EQ(rows[1].status, "blocked_by_bound");
  EXPECT_FALSE(rows[1].solved);
  EXPECT_NEAR(rows[1].residual, 0.19, 1e-12);  // at x = -0.9
}

TEST(ProblemSets, TheBoundedSetGivesItsBoxToTheEnginesThatTakeOne) {
  // auto gets the box and stays in it; MINPACK has none and is judged the same way.
  const ProblemSelection s = select_problems("bounded", problem_set_registry());
  const auto rows = reference::run_suite(*s.set, s.problems, {"auto", "minpack:hybrj"});
  int auto_solved = 0, minpack_solved = 0;
  for (const SuiteRow& r : rows) {
    if (r.solver == "auto") {
      auto_solved += r.solved;
      EXPECT_NE(r.status, "outside_bounds") << r.problem << " " << r.start;
    } else {
      minpack_solved += r.solved;
    }
  }
  EXPECT_EQ(auto_solved, 6);     // all but bullard-biegler from b (docs/solvers.md, "Bounds")
  EXPECT_EQ(minpack_solved, 2);  // measured; unbounded, it leaves the box or F's domain
}

TEST(ProblemSets, AnEngineThatRefusesTheBoxIsARowNotTheEnd) {
  register_once();
  // x = 0.5 on x >= 0: levenberg-marquardt with geodesic acceleration refuses a box.
  TestProblem p = root_test_problem("half", 1, [](const auto& x, auto& f) { f[0] = x[0] - 0.5; },
                                    {{"one", Eigen::VectorXd::Constant(1, 1.0)}});
  p.lower = Eigen::VectorXd::Constant(1, 0.0);
  const ProblemSetEntry set{.name = "half",
                            .problems = [p] { return std::vector<TestProblem>{p}; }};
  const auto rows = reference::run_suite(set, build_problem_set(set),
                                         {"levenberg-marquardt:geodesic=1", "newton"});
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].status, "invalid_input");
  EXPECT_FALSE(rows[0].solved);
  EXPECT_TRUE(rows[1].solved) << rows[1].status;
}

TEST(ProblemSets, AThrowingProblemOrEngineIsARowNotTheEnd) {
  register_once();
  const ProblemSelection s = select_problems("test-hostile", problem_set_registry());
  const std::vector<std::string> solvers = {"newton", "test-throws", "minpack:hybrj",
                                            "kinsol:newton", "gsl:hybridsj"};
  SuiteOptions options;
  options.evaluations_per_dimension = 50;
  const auto rows = reference::run_suite(*s.set, s.problems, solvers, options);
  ASSERT_EQ(rows.size(), solvers.size());
  EXPECT_EQ(row(rows, "hostile", "x0", "test-throws").status, "engine_threw");
  for (const SuiteRow& r : rows) {
    SCOPED_TRACE(r.solver);
    EXPECT_FALSE(r.solved) << r.status;  // F throws beyond 0.5: the root 1 is out of reach
  }
}

// F returns NaN beyond 0.5 without throwing (a model that leaves its domain quietly): every
// solver gets a row, none claims the root, and a point where F is NaN is never "solved".
TEST(ProblemSets, AProblemThatReturnsNanIsARowNeverASolution) {
  const ProblemSetEntry set{
      .name = "test-quiet-nan", .description = "F is NaN beyond 0.5", .problems = [] {
        return std::vector<TestProblem>{root_test_problem(
            "quiet-nan", 1,
            [](const auto& x, auto& f) {
              using T = std::decay_t<decltype(x[0])>;
              f[0] = x[0] > 0.5 ? T(std::numeric_limits<double>::quiet_NaN()) : x[0] - 1.0;
            },
            {{"x0", Eigen::VectorXd::Constant(1, 0.0)}})};
      }};
  const std::vector<TestProblem> problems = build_problem_set(set);
  const std::vector<std::string> solvers = {"newton",        "anderson",      "ceres",
                                            "minpack:hybrj", "kinsol:newton", "gsl:hybridsj",
                                            "gsl:gnewton"};
  SuiteOptions options;
  options.evaluations_per_dimension = 50;
  const auto rows = reference::run_suite(set, problems, solvers, options);
  ASSERT_EQ(rows.size(), solvers.size());
  for (const SuiteRow& r : rows) {
    SCOPED_TRACE(r.solver);
    EXPECT_FALSE(r.solved) << r.status;
    EXPECT_FALSE(r.status.empty());
    EXPECT_FALSE(r.status == "converged" && !(r.residual <= 1e-8)) << r.residual;
  }
}

// A start of 1e308: KINSOL's maximum step 1000 ‖u₀‖ overflowed and its options threw, which
// ended the whole suite. Now every (solver, problem, start) is a row whatever a solver's options
// or set-up throw, and the suite goes on.
TEST(ProblemSets, EverySolverGivesARowForAHugeStart) {
  TestProblem p = root_test_problem(
      "huge", 2,
      [](const auto& x, auto& f) {
        f[0] = x[0] - 1.0;
        f[1] = x[1] - 1.0;
      },
      {{"far", Eigen::Vector2d(1e308, -1e308)}, {"near", Eigen::Vector2d(2.0, 0.0)}});
  const ProblemSetEntry set{.name = "huge",
                            .problems = [p] { return std::vector<TestProblem>{p}; }};
  const std::vector<std::string> solvers = {"kinsol:newton", "kinsol:fp",   "minpack:hybrj",
                                            "gsl:hybridsj",  "gsl:gnewton", "newton",
                                            "auto"};
  SuiteOptions options;
  options.evaluations_per_dimension = 20;
  std::vector<SuiteRow> rows;
  ASSERT_NO_THROW(rows = reference::run_suite(set, build_problem_set(set), solvers, options));
  ASSERT_EQ(rows.size(), 2u * solvers.size());
  for (const SuiteRow& r : rows) {
    SCOPED_TRACE(r.solver + " " + r.start + " " + r.status + " " + r.message);
    EXPECT_FALSE(r.status.empty());
    if (r.start == "near") {
      EXPECT_TRUE(r.solved || r.solver == "kinsol:fp");  // x + F is no contraction
    }
  }
}

// `throw 42` from a user's engine, or from a user's F inside our engines, used to end the
// process (run_suite caught std::exception only): now a row, engine_threw, saying what it was.
TEST(ProblemSets, ANonStandardExceptionIsARowNotTheEnd) {
  register_once();
  const ProblemSetEntry set{.name = "test-42", .problems = [] {
                              return std::vector<TestProblem>{
                                  root_test_problem("throws-42", 1,
                                                    [](const auto& x, auto& f) {
                                                      if (x[0] > 0.5) throw 42;
                                                      f[0] = x[0] - 1.0;
                                                    },
                                                    {{"x0", Eigen::VectorXd::Constant(1, 0.0)}})};
                            }};
  const std::vector<std::string> solvers = {"test-throws-42", "newton",        "anderson",
                                            "auto",           "minpack:hybrj", "kinsol:newton",
                                            "kinsol:fp",      "gsl:gnewton"};
  SuiteOptions options;
  options.evaluations_per_dimension = 50;
  std::vector<SuiteRow> rows;
  ASSERT_NO_THROW(rows = reference::run_suite(set, build_problem_set(set), solvers, options));
  ASSERT_EQ(rows.size(), solvers.size());
  const SuiteRow& engine = row(rows, "throws-42", "x0", "test-throws-42");
  EXPECT_EQ(engine.status, "engine_threw");
  EXPECT_EQ(engine.message, "a non-standard exception");
  EXPECT_FALSE(row(rows, "throws-42", "x0", "newton").solved);
  EXPECT_EQ(row(rows, "throws-42", "x0", "newton").status, "engine_threw");
  for (const SuiteRow& r : rows) EXPECT_FALSE(r.solved) << r.solver << " " << r.status;
}

// A known solution that is not a root, or lies outside the box, made the error column report
// 4.0 for a solver that found the true root: refused, naming set, problem and solution index.
TEST(ProblemSets, AKnownSolutionMustBeARootInsideTheBox) {
  const auto message = [](TestProblem p, double threshold) -> std::string {
    const ProblemSetEntry set{.name = "sols",
                              .problems = [p] { return std::vector<TestProblem>{p}; },
                              .solved_threshold = threshold};
    try {
      build_problem_set(set);
    } catch (const InvalidInput& e) {
      return e.what();
    }
    return "<accepted>";
  };
  TestProblem p = circle_and_line();
  EXPECT_EQ(message(p, 1e-8), "<accepted>");
  p.solutions.push_back(Eigen::Vector2d(2.0, 2.0));  // |F| = 4
  std::string m = message(p, 1e-8);
  EXPECT_NE(m.find("problem set 'sols'"), std::string::npos) << m;
  EXPECT_NE(m.find("problem 'circle-line'"), std::string::npos) << m;
  EXPECT_NE(m.find("known solution 1 is not a root"), std::string::npos) << m;
  EXPECT_NE(m.find("|F(x*)|2 = 4 > 1e-08"), std::string::npos) << m;
  p = circle_and_line();
  p.solutions.insert(p.solutions.begin(), Eigen::Vector2d(-std::sqrt(2.0), -std::sqrt(2.0)));
  m = message(p, 1e-8);  // a root, outside [0, 3]²
  EXPECT_NE(m.find("known solution 0: x[0] is outside the bounds"), std::string::npos) << m;
  // The published digits of a root are not a root at 1e-8; at the set's own looser threshold
  // they are.
  p = circle_and_line();
  p.solutions = {Eigen::Vector2d(1.41421, 1.41421)};
  EXPECT_NE(message(p, 1e-8).find("known solution 0 is not a root"), std::string::npos);
  EXPECT_EQ(message(p, 1e-4), "<accepted>");
  // F throwing at the solution is named too.
  p = hostile();
  p.solutions = {Eigen::VectorXd::Constant(1, 1.0)};
  m = message(p, 1e-8);
  EXPECT_NE(m.find("known solution 0: F throws there: the model left its domain"),
            std::string::npos)
      << m;
  // The built-in sets pass (their published solutions refined to double precision).
  for (const char* name : {"mgh", "bounded", "chua-window"}) {
    EXPECT_NO_THROW(build_problem_set(*problem_set_registry().find(name))) << name;
  }
}

// The budget is the same for every solver, and enforced: no row reports more F evaluations
// than K (n + 1), and an evaluation asked for beyond it is refused (the row is max_evaluations,
// never solved). Before: kinsol:newton used 118 687 of 7 000; at K = 1, 23 rows were solved
// beyond their budget.
TEST(ProblemSets, NoSolverEvaluatesFBeyondItsBudget) {
  register_once();
  const ProblemSelection mgh = select_problems("mgh", problem_set_registry());
  std::vector<std::string> solvers = reference::default_suite_solvers();
  solvers.push_back("kinsol:fp");
  solvers.push_back("kinsol:fp-aa2");
  for (const long k : {1L, 2L, 5L}) {
    SuiteOptions options;
    options.evaluations_per_dimension = k;
    const auto rows = reference::run_suite(*mgh.set, mgh.problems, solvers, options);
    int solved = 0;
    for (const SuiteRow& r : rows) {
      SCOPED_TRACE(r.solver + " " + r.problem + " n=" + std::to_string(r.n) + " " + r.start +
                   " K=" + std::to_string(k));
      EXPECT_LE(r.f_evals, k * (r.n + 1)) << r.status;
      EXPECT_GE(r.f_evals, 0);
      solved += r.solved;
    }
    EXPECT_GT(solved, 0) << k;  // a root within the budget is solved
  }
  // A user's engine that ignores the budget is stopped at it: its evaluations beyond are
  // refused (NaN, the problem's F is not called), the row is max_evaluations, not solved,
  // although the point it returns is the root.
  int calls = 0;
  TestProblem counted = root_test_problem("counted", 1,
                                          [&calls](const auto& x, auto& f) {
                                            ++calls;
                                            f[0] = x[0] - 1.0;
                                          },
                                          {{"x0", Eigen::VectorXd::Constant(1, 0.0)}});
  const ProblemSetEntry set{.name = "counted",
                            .problems = [counted] { return std::vector<TestProblem>{counted}; }};
  const auto problems = build_problem_set(set);
  SuiteOptions options;
  options.evaluations_per_dimension = 3;
  calls = 0;
  const auto rows = reference::run_suite(set, problems, {"test-greedy"}, options);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].status, "max_evaluations");
  EXPECT_FALSE(rows[0].solved);
  EXPECT_EQ(rows[0].f_evals, 6);  // counted at the call, not as the engine reports
  EXPECT_LT(rows[0].residual, 1e-8);
  EXPECT_NE(rows[0].message.find("beyond the budget of 6"), std::string::npos) << rows[0].message;
}

// The references' statuses are names in the suite's vocabulary: lowercase, no spaces (KINSOL's
// flag names were printed as KIN_LINESEARCH_NONCONV or NONE, GSL's as gsl_strerror's
// sentences, "input domain error" for gnewton's singular Jacobian).
TEST(ProblemSets, ReferenceStatusesAreLowercaseNames) {
  const ProblemSelection mgh = select_problems("mgh", problem_set_registry());
  // PETSc's statuses: tests/test_petsc_reference.cpp (a program that starts MPI).
  std::vector<std::string> references = reference::all_reference_solvers();
  std::erase_if(references, [](const std::string& r) { return r.rfind("petsc:", 0) == 0; });
  const auto rows = reference::run_suite(*mgh.set, mgh.problems, references);
  std::set<std::string> statuses;
  for (const SuiteRow& r : rows) {
    statuses.insert(r.status);
    EXPECT_EQ(r.status.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789_"),
              std::string::npos)
        << r.solver << " " << r.problem << " " << r.start << ": '" << r.status << "'";
  }
  EXPECT_TRUE(statuses.count("kin_linesearch_nonconv") || statuses.count("max_evaluations"));
  EXPECT_FALSE(statuses.count("none"));
}

// n = 0, a problems() that throws (anything) or runs out of memory, and n above the dense
// limit: refused naming the set, the problem and the numbers.
TEST(ProblemSets, EmptyHugeAndThrowingSetsAreRefusedNamingThem) {
  const auto message = [](std::function<std::vector<TestProblem>()> problems) -> std::string {
    const ProblemSetEntry set{.name = "odd", .problems = std::move(problems)};
    try {
      build_problem_set(set);
    } catch (const InvalidInput& e) {
      return e.what();
    }
    return "<accepted>";
  };
  std::string m = message([] {
    return std::vector<TestProblem>{
        root_test_problem("nothing", 0, [](const auto&, auto&) {}, {{"s", Eigen::VectorXd(0)}})};
  });
  // RootProblem refuses n = 0 itself, inside the set's problems(): the set is named.
  EXPECT_NE(m.find("problem set 'odd': building its problems threw: RootProblem: dimensions n = 0"),
            std::string::npos)
      << m;
  m = message([]() -> std::vector<TestProblem> { throw std::runtime_error("no licence"); });
  EXPECT_NE(m.find("problem set 'odd': building its problems threw: no licence"), std::string::npos)
      << m;
  m = message([]() -> std::vector<TestProblem> { throw 42; });
  EXPECT_NE(m.find("problem set 'odd': building its problems threw: a non-standard exception"),
            std::string::npos)
      << m;
  m = message([]() -> std::vector<TestProblem> { throw std::bad_alloc(); });
  EXPECT_NE(m.find("problem set 'odd': building its problems ran out of memory"), std::string::npos)
      << m;
  // Above the dense limit with a dense Jacobian (every F_i reads every x_j; a sparse F of that
  // size is accepted: test_large_set.cpp).
  const Index big = kMaxProblemDimension + 1;
  m = message([big] {
    return std::vector<TestProblem>{
        root_test_problem("big", big, [](const auto& x, auto& f) { f = x.array() - x.sum(); },
                          {{"s", Eigen::VectorXd::Zero(big)}})};
  });
  EXPECT_NE(m.find("problem 'big' (n = 2001): n = 2001 is above the limit of 2000 unknowns"),
            std::string::npos)
      << m;
  // A start label of control characters is echoed escaped.
  m = message([] {
    TestProblem p = circle_and_line();
    p.starts[0].x = Eigen::Vector3d::Zero();
    p.starts[0].label = "\x1b[31mred\n";
    return std::vector<TestProblem>{p};
  });
  EXPECT_NE(m.find("start '\\x1b[31mred\\x0a' has size 3"), std::string::npos) << m;
}

// What the table prints of a row without an answer: its reason, on the next line.
TEST(ProblemSets, TheTableSaysWhyARowHasNoAnswer) {
  register_once();
  cli::SuiteArguments args;
  args.solvers = "test-throws-42,test-throws";
  std::ostringstream out, err;
  cli::run_problem_suite({"test-set/cosine"}, args, "solve", out, err);
  EXPECT_NE(out.str().find("engine_threw"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("    a non-standard exception\n"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("    a user's engine failed\n"), std::string::npos) << out.str();
}

// What fuzz_suite_report checks, pinned: a start label from a user's plugin with invalid UTF-8
// made nlohmann::json's dump() throw (the --json output ended with an exception); it is U+FFFD
// in the JSON, the bytes as given in the CSV (quoted), escaped in the table.
TEST(ProblemSets, TheWritersTakeAnyLabel) {
  SuiteRow r;
  r.set = "s";
  r.problem = "p";
  r.n = 1;
  r.start = "a,\"b\"\n\xff\x1b[31m";
  r.solver = "newton";
  r.residual = std::numeric_limits<double>::quiet_NaN();
  r.ns = 5e-324;
  r.status = "engine_threw";
  r.message = "line\r\nbreak";
  const std::vector<SuiteRow> rows = {r};
  std::string dumped;
  ASSERT_NO_THROW(dumped = cli::suite_to_json(rows).dump());
  const auto back = nlohmann::json::parse(dumped);
  EXPECT_EQ(back[0]["start"], "a,\"b\"\n\xEF\xBF\xBD\x1b[31m");
  EXPECT_TRUE(back[0]["residual"].is_null());
  EXPECT_EQ(back[0]["ns"].get<double>(), 5e-324);
  const std::string csv = cli::suite_to_csv(rows);
  EXPECT_NE(csv.find(",\"a,\"\"b\"\"\n\xff\x1b[31m\","), std::string::npos) << csv;
  // The columns added after message: scaled_residual, x (empty: no answer), evals_past_progress.
  EXPECT_NE(csv.find(",\"line\r\nbreak\",0,,0\n"), std::string::npos) << csv;
  std::ostringstream table;
  cli::print_suite_tables(rows, 1e-8, table);
  EXPECT_NE(table.str().find("start a,\"b\"\\x0a\\xff\\x1b[31m"), std::string::npos) << table.str();
  EXPECT_NE(table.str().find("    line\\x0d\\x0abreak\n"), std::string::npos) << table.str();

  // Names whose escapes run long (each byte of invalid UTF-8 is "\xNN"): the per-solver line
  // holds them whole and ends its line (a 400-byte buffer cut it mid-escape, found by
  // fuzz_suite_report).
  SuiteRow idle = r;
  idle.solver = std::string(48, '\xda');
  idle.problem = std::string(100, '\xdb');
  idle.evals_past_progress = 7;
  std::ostringstream long_table;
  cli::print_suite_tables({idle}, 1e-8, long_table);
  const std::string text = long_table.str();
  const std::size_t at = text.find(" idle      7 (");
  ASSERT_NE(at, std::string::npos) << text;
  EXPECT_NE(text.find(")\nidle: the most F evaluations", at), std::string::npos) << text;
}

TEST(ProblemSets, MalformedProblemsAreRefusedNamingTheProblem) {
  const auto refused = [](TestProblem p) -> std::string {
    try {
      validate_test_problem(p, "problem set 'x'");
    } catch (const InvalidInput& e) {
      return e.what();
    }
    return "<accepted>";
  };
  const auto expect = [&](TestProblem p, const std::string& part) {
    const std::string m = refused(std::move(p));
    EXPECT_NE(m.find("problem set 'x'"), std::string::npos) << m;
    EXPECT_NE(m.find(part), std::string::npos) << m;
  };
  EXPECT_EQ(refused(circle_and_line()), "<accepted>");
  TestProblem p = circle_and_line();
  p.starts[0].x = Eigen::Vector3d::Zero();
  expect(p, "start 'near' has size 3");
  p = circle_and_line();
  p.starts[1].x[0] = std::numeric_limits<double>::quiet_NaN();
  expect(p, "start 'far' is not finite");
  p = circle_and_line();
  p.starts[1].x[0] = 5.0;
  expect(p, "start 'far': x[0] is outside the bounds");
  p = circle_and_line();
  p.lower[1] = 4.0;
  expect(p, "lower[1] = 4 > upper[1] = 3");
  p = circle_and_line();
  p.upper = Eigen::VectorXd::Zero(3);
  expect(p, "upper has size 3");
  p = circle_and_line();
  p.starts.clear();
  expect(p, "no start");
  p = circle_and_line();
  p.starts[1].label = "near";
  expect(p, "start 'near' is listed twice");
  p = circle_and_line();
  p.solutions = {Eigen::VectorXd::Zero(1)};
  expect(p, "known solution 0 has size 1");
  p = circle_and_line();
  p.name = "a b";
  expect(p, "problem name 'a b'");
  expect(TestProblem{.name = "no-jacobian",
                     .residual = RootProblem<Dynamic>::from_map(
                         [](const Eigen::VectorXd& x, Eigen::VectorXd& f) { f = x; }, 2, 2),
                     .starts = {{"s", Eigen::Vector2d::Zero()}}},
         "no Jacobian");
  expect(TestProblem{.name = "not-square",
                     .residual = RootProblem<Dynamic>::with_autodiff(
                         [](const auto& x, auto& f) {
                           f[0] = x[0];
                           f[1] = x[1];
                           f[2] = x[0] * x[1];
                         },
                         2, 3),
                     .starts = {{"s", Eigen::Vector2d::Zero()}}},
         "F has 3 components for 2 unknowns");
  // A set listing one (name, n) twice, or nothing.
  const ProblemSetEntry twice{
      .name = "twice", .problems = [] {
        return std::vector<TestProblem>{circle_and_line(), circle_and_line()};
      }};
  EXPECT_THROW(build_problem_set(twice), InvalidInput);
  const ProblemSetEntry empty{.name = "empty",
                              .problems = [] { return std::vector<TestProblem>{}; }};
  EXPECT_THROW(build_problem_set(empty), InvalidInput);
}

TEST(ProblemSets, SelectorsNameSetsProblemsAndSizes) {
  register_once();
  const auto& sets = problem_set_registry();
  EXPECT_EQ(select_problems("mgh/chebyquad", sets).problems.size(), 5u);
  const auto seven = select_problems("mgh/chebyquad:n=7", sets);
  ASSERT_EQ(seven.problems.size(), 1u);
  EXPECT_EQ(seven.problems[0].size(), 7);
  EXPECT_EQ(select_problems("chua-window", sets).problems.size(), 1u);
  const auto message = [&](const std::string& selector) -> std::string {
    try {
      select_problems(selector, sets);
    } catch (const InvalidInput& e) {
      return e.what();
    }
    return "<accepted>";
  };
  const std::string no_problem = message("mgh/rosenbrok");
  EXPECT_NE(no_problem.find("has no problem 'rosenbrok'"), std::string::npos) << no_problem;
  EXPECT_NE(no_problem.find("rosenbrock:n=2"), std::string::npos) << no_problem;
  const std::string no_set = message("mhg/rosenbrock");
  EXPECT_NE(no_set.find("unknown problem set 'mhg'"), std::string::npos) << no_set;
  EXPECT_NE(no_set.find("test-set"), std::string::npos) << no_set;
  EXPECT_NE(message("mgh/chebyquad:n=x").find("':n=K'"), std::string::npos);
  EXPECT_NE(message("mgh/chebyquad:n=4").find("has no problem"), std::string::npos);
}

TEST(ProblemSets, ADuplicateSetNameNamesBothSources) {
  register_once();
  try {
    problem_set_registry().add(ProblemSetEntry{.name = "test-set"}, "another plugin");
    FAIL() << "accepted";
  } catch (const InvalidInput& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("another plugin"), std::string::npos) << m;
    EXPECT_NE(m.find("test_problem_sets"), std::string::npos) << m;
  }
  EXPECT_EQ(problem_set_registry().source("test-set"), "test_problem_sets");
}

TEST(ProblemSets, TheChuaWindowSetIsTheFixedPointOfThePaper) {
  const ProblemSelection s = select_problems("chua-window/window", problem_set_registry());
  ASSERT_EQ(s.problems.size(), 1u);
  const TestProblem& p = s.problems[0];
  ASSERT_TRUE(p.fixed_point.has_value());
  ASSERT_EQ(p.solutions.size(), 1u);
  // G(x*) = x* and F(x*) = 0 at the true initial state; ∂F = ∂G − I.
  Eigen::VectorXd g(3), f(3);
  p.fixed_point->evaluate(p.solutions[0], g);
  p.residual.evaluate(p.solutions[0], f);
  EXPECT_LT((g - p.solutions[0]).norm(), 1e-12);
  EXPECT_LT(f.norm(), 1e-12);
  Eigen::MatrixXd jg, jf;
  p.fixed_point->jacobian(p.starts[0].x, jg);
  p.residual.jacobian(p.starts[0].x, jf);
  EXPECT_LT((jf - (jg - Eigen::MatrixXd::Identity(3, 3))).norm(), 1e-12);
  const auto rows = reference::run_suite(*s.set, s.problems, {"newton", "kinsol:fp-aa2"});
  for (const SuiteRow& r : rows) {
    if (r.start == "x1") {
      EXPECT_TRUE(r.solved) << r.solver << " " << r.status;
    }
  }
}

TEST(ProblemSets, TheCliPrintsTheTableJsonAndCsvOfAUsersSet) {
  register_once();
  cli::SuiteArguments args;
  args.solvers = "newton,kinsol:newton";
  std::ostringstream out, err;
  cli::run_problem_suite({"test-set"}, args, "suite", out, err);
  EXPECT_NE(out.str().find("circle-line n=2 (start near)"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("|x-x*|inf"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("solved (|F|2 <= 1e-8 at the returned point)"), std::string::npos);

  const auto csv = std::filesystem::temp_directory_path() / "nlobs_test_problem_sets.csv";
  args.json = true;
  args.csv = csv.string();
  args.threshold = 1e-300;  // nothing but an exact root counts
  std::ostringstream json_out;
  cli::run_problem_suite({"test-set/cosine", "mgh/rosenbrock"}, args, "solve", json_out, err);
  const auto rows = nlohmann::json::parse(json_out.str());
  ASSERT_EQ(rows.size(), 2u * 1u + 2u * 3u);  // solvers x starts
  for (const auto& r : rows) {
    for (const char* key : {"set", "problem", "n", "start", "start_scale", "solver", "solved",
                            "residual", "error", "f_evals", "j_evals", "ns", "status", "message",
                            "scaled_residual", "x", "evals_past_progress"}) {
      ASSERT_TRUE(r.contains(key)) << key << " missing in " << r.dump();
    }
    // The threshold given is the one judged by.
    EXPECT_EQ(r["solved"].get<bool>(),
              r["residual"].is_number() && r["residual"].get<double>() <= 1e-300)
        << r.dump();
  }
  std::ifstream file(csv);
  std::string header, line;
  std::getline(file, header);
  EXPECT_EQ(header,
            "set,problem,n,start,start_scale,solver,solved,residual,error,f_evals,j_evals,ns,"
            "status,message,scaled_residual,x,evals_past_progress");
  int lines = 0;
  while (std::getline(file, line)) ++lines;
  EXPECT_EQ(lines, 8);
  std::filesystem::remove(csv);

  // Bad input, before anything runs.
  args = {};
  EXPECT_THROW(cli::run_problem_suite({"test-set/circle-line"}, args, "suite", out, err),
               std::invalid_argument);
  args.solvers = "newton,nonsense";
  try {
    cli::run_problem_suite({"test-set"}, args, "suite", out, err);
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("unknown engine 'nonsense'"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("test-picard"), std::string::npos);  // a user's engine
  }
  args = {};
  args.starts = "near,nowhere";
  EXPECT_THROW(cli::run_problem_suite({"test-set"}, args, "suite", out, err),
               std::invalid_argument);
  args = {};
  args.threshold = -1.0;
  EXPECT_THROW(cli::run_problem_suite({"test-set"}, args, "suite", out, err), InvalidInput);
  // A CSV target that cannot be written is refused before the first solve, not after the run.
  args = {};
  args.solvers = "test-counts";
  CountingEngine::solves = 0;
  for (const std::string& target : {std::filesystem::temp_directory_path().string(),  // a directory
                                    std::string("/nonexistent-nlobs-dir/rows.csv")}) {
    args.csv = target;
    EXPECT_THROW(cli::run_problem_suite({"test-set/cosine"}, args, "solve", out, err),
                 std::runtime_error)
        << target;
    EXPECT_EQ(CountingEngine::solves, 0) << target;
  }
}

TEST(ProblemSets, ASolverOrProblemNamedTwiceRunsOnce) {
  register_once();
  cli::SuiteArguments args;
  args.solvers = "test-counts,newton,test-counts";
  args.json = true;
  std::ostringstream out, err;
  cli::run_problem_suite({"test-set/cosine", "test-set", "test-set/cosine:n=3"}, args, "solve", out,
                         err);
  // test-set holds circle-line (starts near, far) and cosine (start zero): three pairs, each
  // once, with each solver once.
  const auto rows = nlohmann::json::parse(out.str());
  ASSERT_EQ(rows.size(), 3u * 2u) << out.str();
  EXPECT_EQ(rows[0]["solver"], "test-counts");
  EXPECT_EQ(rows[1]["solver"], "newton");
  EXPECT_NE(err.str().find("solver 'test-counts' is listed more than once; it runs once"),
            std::string::npos)
      << err.str();
  EXPECT_NE(err.str().find("test-set/cosine:n=3 is selected more than once; it runs once"),
            std::string::npos)
      << err.str();
}

// --starts is judged against every selected problem together, before the first solve.
TEST(ProblemSets, StartLabelsAreCheckedAgainstEverySelectedProblem) {
  register_once();
  cli::SuiteArguments args;
  args.solvers = "test-counts";
  args.json = true;
  // A label one selector's problems have and another's lack runs where it is (it was refused
  // for the second selector after the first had run).
  args.starts = "zero,x1";
  std::ostringstream out, err;
  cli::run_problem_suite({"test-set/cosine", "mgh/rosenbrock"}, args, "solve", out, err);
  auto rows = nlohmann::json::parse(out.str());
  ASSERT_EQ(rows.size(), 2u) << out.str();
  EXPECT_EQ(rows[0]["start"], "zero");
  EXPECT_EQ(rows[1]["start"], "x1");
  // A problem named twice and a label: once (the second, emptied selection had no start left
  // and was refused).
  args.starts = "zero";
  out.str("");
  cli::run_problem_suite({"test-set/cosine", "test-set/cosine"}, args, "solve", out, err);
  rows = nlohmann::json::parse(out.str());
  EXPECT_EQ(rows.size(), 1u) << out.str();
  // A label no selected problem has: the flag, the label and the labels there are, before any
  // solve. circle-line's "near" is in the set but not in the selection.
  CountingEngine::solves = 0;
  args.starts = "zero,near";
  try {
    cli::run_problem_suite({"mgh/rosenbrock", "test-set/cosine"}, args, "solve", out, err);
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "nlobs solve --starts: no selected problem (mgh/rosenbrock, test-set/cosine) "
                  "has a start 'near'; their starts: x1, x10, x100, zero"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(CountingEngine::solves, 0);
}

}  // namespace
}  // namespace nlobs
