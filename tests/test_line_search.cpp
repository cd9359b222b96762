// LineSearch (line_search.hpp): the Armijo test on a path the caller defines, the full step, a
// path that does not descend, a bound that holds x, a budget that runs out, m undefined (NaN)
// and its validation; then the engines that use it (newton, broyden) on a problem nlobs does
// not ship whose full Newton steps diverge out of F's domain.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#include "nlobs/common/invalid_input.hpp"
#include "nlobs/solvers/broyden_engine.hpp"
#include "nlobs/solvers/line_search.hpp"
#include "nlobs/solvers/newton_engine.hpp"
#include "nlobs/solvers/root_adapter.hpp"

namespace nlobs {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The path x(t) = x + t d on m(x) = x⁴ − x from x = 1, d = −3 (m'(1) = 3, so −∇m is d):
// δm(t) = m'(x)·t d. Records the trials.
struct QuarticPath {
  double x = 1.0, d = -3.0, t = 0.0;
  int budget = 1000;  // merit evaluations allowed
  std::vector<double> trials;
  static double m(double y) { return y * y * y * y - y; }
  bool exhausted() const { return static_cast<int>(trials.size()) >= budget; }
  bool move(double step) {
    t = step;
    return false;
  }
  double slope() const { return (4.0 * x * x * x - 1.0) * t * d; }
  double merit() {
    trials.push_back(t);
    return m(x + t * d);
  }
};

TEST(LineSearch, AcceptsTheFirstTrialThatMeetsArmijo) {
  static_assert(LineSearchPath<QuarticPath>);
  QuarticPath path;
  const LineSearch rule{.sufficient_decrease = 1e-4, .shrink = 0.5, .max_backtracks = 30};
  const LineSearch::Result r = rule.search(path, 1.0, QuarticPath::m(1.0));
  ASSERT_TRUE(r.accepted());
  ASSERT_EQ(r.trials, static_cast<int>(path.trials.size()));
  // The accepted trial meets the test; every earlier one (t/ρ, t/ρ², …) did not.
  const auto armijo = [&](double t) {
    return QuarticPath::m(1.0 + t * path.d) <= QuarticPath::m(1.0) + 1e-4 * 3.0 * t * path.d;
  };
  EXPECT_TRUE(armijo(r.t));
  EXPECT_EQ(r.merit, QuarticPath::m(1.0 + r.t * path.d));
  for (std::size_t k = 0; k + 1 < path.trials.size(); ++k) {
    EXPECT_FALSE(armijo(path.trials[k])) << "t = " << path.trials[k];
    EXPECT_EQ(path.trials[k + 1], 0.5 * path.trials[k]);
  }
  EXPECT_GT(r.trials, 1);  // t = 1 overshoots to x = −2, where m = 18
}

TEST(LineSearch, FullStepTakesTheFirstTrialWhereTheMeritIsDefined) {
  QuarticPath path;
  const LineSearch full{.kind = LineSearch::Kind::kFullStep};
  const LineSearch::Result r = full.search(path, 1.0, QuarticPath::m(1.0));
  EXPECT_TRUE(r.accepted());  // m rose from 0 to 18: no globalisation
  EXPECT_EQ(r.t, 1.0);
  EXPECT_EQ(r.trials, 1);
  EXPECT_EQ(r.merit, 18.0);
}

// A path scripted trial by trial.
struct ScriptedPath {
  std::vector<double> merits, slopes;
  std::size_t next = 0;
  bool held = false;
  int budget = 1000, evaluated = 0;
  bool exhausted() const { return evaluated >= budget; }
  bool move(double) { return held; }
  double slope() const { return slopes[std::min(next, slopes.size() - 1)]; }
  double merit() {
    ++evaluated;
    return merits[std::min(next++, merits.size() - 1)];
  }
};

TEST(LineSearch, UndefinedMeritIsBacktrackedOverAndNeverAccepted) {
  // m undefined (F not finite) at the first two trials, then a decrease.
  ScriptedPath path{.merits = {kNaN, kNaN, 0.5}, .slopes = {-1.0}};
  const LineSearch rule{.max_backtracks = 5};
  LineSearch::Result r = rule.search(path, 1.0, 1.0);
  EXPECT_TRUE(r.accepted());
  EXPECT_EQ(r.trials, 3);
  EXPECT_EQ(r.t, 0.25);

  ScriptedPath nowhere{.merits = {kNaN}, .slopes = {-1.0}};
  r = rule.search(nowhere, 1.0, 1.0);
  EXPECT_EQ(r.outcome, LineSearch::Outcome::kNoDecrease);
  EXPECT_EQ(r.trials, 6);  // the first and max_backtracks more

  ScriptedPath full_nan{.merits = {kNaN}, .slopes = {-1.0}};
  r = LineSearch{.kind = LineSearch::Kind::kFullStep}.search(full_nan, 1.0, 1.0);
  EXPECT_EQ(r.outcome, LineSearch::Outcome::kNoDecrease);
  EXPECT_EQ(r.trials, 1);
}

TEST(LineSearch, NaNSlopeFailsTheTest) {
  // A slope that is not a number (an overflowed gradient) must not let m rise or stay: with the
  // min(·, m(x)) alone it would accept m = m(x).
  ScriptedPath path{.merits = {1.0}, .slopes = {kNaN}};
  const LineSearch::Result r = LineSearch{.max_backtracks = 2}.search(path, 1.0, 1.0);
  EXPECT_EQ(r.outcome, LineSearch::Outcome::kNoDecrease);
}

TEST(LineSearch, NonDescendingPathAllowsNoIncreaseOrEndsWhenDescentIsRequired) {
  // δm > 0 (a projected path that climbs): Armijo's bound exceeds m(x); the min keeps m(x).
  ScriptedPath climbing{.merits = {1.0 + 1e-9, 1.0}, .slopes = {0.5}};
  LineSearch::Result r = LineSearch{}.search(climbing, 1.0, 1.0);
  EXPECT_TRUE(r.accepted());
  EXPECT_EQ(r.trials, 2);  // 1 + 1e-9 refused although below 1 + c·0.5
  EXPECT_EQ(r.merit, 1.0);

  ScriptedPath required{.merits = {0.0}, .slopes = {0.0}};
  r = LineSearch{.require_descent = true}.search(required, 1.0, 1.0);
  EXPECT_EQ(r.outcome, LineSearch::Outcome::kNotDescent);
  EXPECT_EQ(required.evaluated, 0);  // m not evaluated along a path that does not descend
}

TEST(LineSearch, HeldPathAndSpentBudgetEndTheSearch) {
  ScriptedPath held{.merits = {0.0}, .slopes = {-1.0}, .held = true};
  LineSearch::Result r = LineSearch{}.search(held, 1.0, 1.0);
  EXPECT_EQ(r.outcome, LineSearch::Outcome::kHeld);
  EXPECT_EQ(held.evaluated, 0);

  ScriptedPath spent{.merits = {2.0}, .slopes = {-1.0}, .budget = 3};
  r = LineSearch{}.search(spent, 1.0, 1.0);
  EXPECT_EQ(r.outcome, LineSearch::Outcome::kExhausted);
  EXPECT_EQ(r.trials, 3);
  EXPECT_EQ(spent.evaluated, 3);
}

TEST(LineSearch, HugeMeritStillDecreases) {
  // m(x) = 1e300, slopes of 1e300: the bound m + c δm stays finite and the test works.
  ScriptedPath path{.merits = {1e300, 0.9e300}, .slopes = {-1e300}};
  const LineSearch::Result r = LineSearch{}.search(path, 1.0, 1e300);
  ASSERT_TRUE(r.accepted());
  EXPECT_EQ(r.trials, 2);
}

TEST(LineSearch, ValidateRefusesEachBadField) {
  const auto refused = [](LineSearch rule, const std::string& field) {
    try {
      rule.validate();
    } catch (const InvalidInput& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("LineSearch::" + field), std::string::npos) << what;
      return true;
    }
    return false;
  };
  EXPECT_NO_THROW(LineSearch{}.validate());
  EXPECT_TRUE(refused({.sufficient_decrease = 0.0}, "sufficient_decrease"));
  EXPECT_TRUE(refused({.sufficient_decrease = 1.0}, "sufficient_decrease"));
  EXPECT_TRUE(refused({.sufficient_decrease = kNaN}, "sufficient_decrease"));
  EXPECT_TRUE(refused({.shrink = 0.0}, "shrink"));  // t = 0 would "accept" x itself
  EXPECT_TRUE(refused({.shrink = 1.0}, "shrink"));
  EXPECT_TRUE(refused({.shrink = kNaN}, "shrink"));
  EXPECT_TRUE(refused({.max_backtracks = -1}, "max_backtracks"));
  EXPECT_TRUE(refused({.kind = static_cast<LineSearch::Kind>(7)}, "kind"));
}

// F(x) = atan(x), defined only for |x| < 5 (NaN beyond): the full Newton step from x = 1.5
// overshoots further each time (|x| grows) and leaves the domain; the line search backtracks
// into it and converges to the root 0.
FixedPointProblem<1> bounded_arctan() {
  return to_fixed_point(RootProblem<1>::with_autodiff([](const auto& x) {
    using std::abs, std::atan;
    using T = typename std::decay_t<decltype(x)>::Scalar;
    return Eigen::Matrix<T, 1, 1>(abs(x[0]) < 5.0 ? atan(x[0]) : T(kNaN));
  }));
}

TEST(LineSearch, NewtonAndBroydenBacktrackIntoTheDomain) {
  SolverOptions options;
  options.stop.residual_tolerance = 1e-12;
  const FixedPointProblem<1> problem = bounded_arctan();

  Vector<1> x(1.5);
  const Summary plain = NewtonEngine<1>({}, options).solve(problem, x);
  EXPECT_FALSE(plain.usable()) << plain.brief_report();

  x = Vector<1>(1.5);
  const Summary searched = NewtonEngine<1>({.line_search = true}, options).solve(problem, x);
  ASSERT_TRUE(searched.converged()) << searched.full_report();
  EXPECT_LE(std::abs(x[0]), 1e-12);

  x = Vector<1>(1.5);
  const Summary broyden = BroydenEngine<1>({}, options).solve(problem, x);
  ASSERT_TRUE(broyden.converged()) << broyden.full_report();
  EXPECT_LE(std::abs(x[0]), 1e-12);
}

}  // namespace
}  // namespace nlobs
