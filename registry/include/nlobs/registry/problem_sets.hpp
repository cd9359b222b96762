#pragma once
// Problem sets: named lists of square systems F(x) = 0, or fixed points x = G(x), each with one
// or more starts, optional box bounds and optional known solutions. `nlobs suite SET` runs every
// listed engine and reference solver on every (problem, start) and judges all alike;
// `nlobs solve SET/NAME` runs one problem. The built-in sets (chua-window, mgh) are registered
// exactly as a user's set is (docs/extending.md).
#include <Eigen/Core>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "nlobs/common/named_registry.hpp"
#include "nlobs/solvers/box_bounds.hpp"
#include "nlobs/solvers/problem.hpp"

namespace nlobs {

struct ProblemStart {
  std::string label{};  // a column of the tables: "x1", "x10", "guess"
  Eigen::VectorXd x{};  // of the problem's size, finite, inside the bounds
  double scale = 1.0;   // the factor of a standard start (MGH: 1, 10, 100), `start_scale` in JSON
};

struct TestProblem {
  // Unique in its set together with n; letters, digits and _ . + - (it is typed on the command
  // line as SET/NAME or SET/NAME:n=K).
  std::string name;
  // F: Rⁿ → Rⁿ with a Jacobian (AD or the user's): what every solver is judged on (‖F(x)‖₂), and
  // what the references (MINPACK, KINSOL Newton, GSL) solve.
  RootProblem<Dynamic> residual;
  // G, when the problem is posed as x = G(x) (then F(x) = G(x) − x): what our engines and
  // KINSOL's fixed-point strategies iterate. Empty: G(x) = x + F(x) (to_fixed_point, Ψ = I).
  std::optional<FixedPointProblem<Dynamic>> fixed_point{};
  std::vector<ProblemStart> starts{};
  // lower ≤ x ≤ upper, each empty for no bound on that side (±inf entries allowed): a point
  // outside is not a solution (status `outside_bounds`).
  Eigen::VectorXd lower{}, upper{};
  // Strict bounds (lower_i < x_i, x_i < upper_i; BoxBounds): one flag per bound, each empty for
  // a closed side. A point on a strict bound is outside; the engines that take strict bounds
  // never evaluate F there; in the suite Ceres and NLopt get a closed box √ε inside.
  StrictBounds strict_lower{}, strict_upper{};
  // Known solutions: the suite reports the ∞-norm distance of the answer to the nearest one.
  std::vector<Eigen::VectorXd> solutions{};
  // KINSOL's scaling (its u_scale and f_scale: the solver's norms are those of D_u x and D_f F,
  // D = diag(scale)); each empty (all ones) or of size n, finite and > 0. The suite judges
  // ‖D_f F(x)‖₂ (`scaled_residual`): a problem whose components live on different scales (a
  // concentration of 1e-6 beside a temperature of 300) states what "small" means per equation.
  Eigen::VectorXd u_scale{}, f_scale{};
  std::string description{};

  Index size() const { return residual.size(); }
  // ‖D_f f‖₂ (‖f‖₂ without an f_scale), inf when f is not finite; f of size n.
  double scaled_norm(const Eigen::VectorXd& f) const {
    if (!f.allFinite()) return std::numeric_limits<double>::infinity();
    const double norm =
        f_scale.size() == f.size() ? f.cwiseProduct(f_scale).stableNorm() : f.stableNorm();
    return std::isfinite(norm) ? norm : std::numeric_limits<double>::infinity();
  }
  // The box as an engine takes it (Engine::set_bounds).
  BoxBounds bounds() const { return {lower, upper, strict_lower, strict_upper}; }
  // The first component of x (of the problem's size) outside the box (on a strict bound
  // included); none inside.
  std::optional<Index> first_outside_bounds(const Eigen::VectorXd& x) const {
    for (Index i = 0; i < x.size(); ++i) {
      if (lower.size() == x.size() && (x[i] < lower[i] || (strict_lower.size() == x.size() &&
                                                           strict_lower[i] && x[i] == lower[i]))) {
        return i;
      }
      if (upper.size() == x.size() && (x[i] > upper[i] || (strict_upper.size() == x.size() &&
                                                           strict_upper[i] && x[i] == upper[i]))) {
        return i;
      }
    }
    return std::nullopt;
  }
};

// F(x) = 0 with F generic in its scalar type (f(x, out) or out = f(x)): ∂F by forward-mode AD.
template <typename F>
TestProblem root_test_problem(std::string name, Index n, F f, std::vector<ProblemStart> starts) {
  return TestProblem{.name = std::move(name),
                     .residual = RootProblem<Dynamic>::with_autodiff(std::move(f), n, n),
                     .starts = std::move(starts)};
}

// x = G(x) with G generic in its scalar type: G and F(x) = G(x) − x, both with AD Jacobians.
template <typename G>
TestProblem fixed_point_test_problem(std::string name, Index n, G g,
                                     std::vector<ProblemStart> starts) {
  auto f = [g](const auto& x, auto& out) mutable {
    detail::invoke_map(g, x, out);
    out -= x;
  };
  return TestProblem{.name = std::move(name),
                     .residual = RootProblem<Dynamic>::with_autodiff(std::move(f), n, n),
                     .fixed_point = FixedPointProblem<Dynamic>::with_autodiff(std::move(g), n),
                     .starts = std::move(starts)};
}

// The largest n of a problem whose Jacobian is dense: the dense solvers of the suite keep n×n
// matrices (a Jacobian, its factorisation, MINPACK's and KINSOL's copies), 32 MB each at
// n = 2000. A problem above it needs a sparse Jacobian (declared, or detected by with_autodiff at
// its first start), and the suite runs no dense reference solver on it.
inline constexpr Index kMaxProblemDimension = 2000;
// The largest n of any problem (10⁷ unknowns: 80 MB a vector).
inline constexpr Index kMaxSparseProblemDimension = 10'000'000;

// Throws InvalidInput naming `where` and the problem: a bad name, n = 0, n above
// kMaxProblemDimension without a sparse Jacobian (or above kMaxSparseProblemDimension), a
// non-square F or one without a Jacobian, a fixed-point map of another
// size, no start, a start, bound or solution of the wrong size, a non-finite start or solution,
// lower > upper, a start outside the bounds, a u_scale or f_scale of the wrong size or with an
// entry not finite and > 0, and a known solution (named by its index) outside the bounds or not a
// root: ‖D_f F(x*)‖₂ > solution_threshold, F not finite there or F throwing there
// (the suite's error column measures the distance to the known solutions: a wrong one would
// report a solver that found the true root as far off). build_problem_set passes the set's
// solved_threshold.
void validate_test_problem(const TestProblem& problem, std::string_view where,
                           double solution_threshold = 1e-8);

struct ProblemSetEntry {
  std::string name{};
  std::string description{};
  // Builds the problems when a run asks for them (a set may be large or slow to set up).
  std::function<std::vector<TestProblem>()> problems{};
  // The default of --threshold: solved when ‖D_f F(x)‖₂ ≤ this at the returned point (D_f the
  // problem's f_scale, the identity without one).
  double solved_threshold = 1e-8;
  // A set of run-time size ("SET:n=K", "SET/NAME:n=K"): its problems built for about K unknowns
  // (each takes the size nearest K its structure allows, a square grid's m² for instance). Empty:
  // the set's sizes are those `problems` builds.
  std::function<std::vector<TestProblem>(Index n)> problems_of_size{};
  // What `nlobs suite SET` runs when --solvers is not given (empty: the suite's default list,
  // reference::default_suite_solvers()).
  std::vector<std::string> default_solvers{};
};

// NamedRegistry refuses a set without problems().
inline std::string missing_part(const ProblemSetEntry& e) {
  return e.problems ? std::string() : std::string("has no problems()");
}

NamedRegistry<ProblemSetEntry>& problem_set_registry();

// The set's problems, each validated (known solutions at the set's solved_threshold), (name, n)
// unique: InvalidInput "problem set 'S': …", also when problems() throws (anything: its text,
// "a non-standard exception" for `throw 42`, "not enough memory" for std::bad_alloc). With `n`,
// problems_of_size(n) builds them: InvalidInput for a set without it, or n outside
// 1 .. kMaxSparseProblemDimension.
std::vector<TestProblem> build_problem_set(const ProblemSetEntry& set,
                                           std::optional<Index> n = std::nullopt);

// "SET" (all its problems), "SET:n=K" (a set of run-time size at K), "SET/NAME" (every size of
// NAME) or "SET/NAME:n=K": the problems it selects. InvalidInput for an unknown set (listing the
// sets) or problem (listing the set's), or a size the set does not have.
struct ProblemSelection {
  const ProblemSetEntry* set = nullptr;
  std::vector<TestProblem> problems{};
};
ProblemSelection select_problems(std::string_view selector,
                                 const NamedRegistry<ProblemSetEntry>& registry);

}  // namespace nlobs
