#pragma once
// A backtracking line search on a merit function m along a path x(t) that its caller defines
// (PETSc's SNESLineSearch "bt" without the cubic fit, and "basic"; LBFGS++'s backtracking
// policy): the trials t = t₀, ρ t₀, ρ² t₀, … (at most max_backtracks shrinks), the first
// accepted ending the search:
//   kBacktracking  m(x(t)) ≤ min(m(x) + c δm(t), m(x))   (Armijo; [NW06] (3.4), [DS96] §6.3)
//   kFullStep      the first trial only, accepted where m is defined (no globalisation)
// δm(t) is the path's first-order change of m from x to x(t), ∇mᵀ(x(t) − x); for m = ‖F‖₂² and
// the Newton step d = −J_F⁻¹F on x(t) = x + t d it is −2t‖F‖₂², the test in its usual form
// ‖F(x + t d)‖₂² ≤ (1 − 2ct)‖F‖₂². The min keeps a path that does not descend (a projected one,
// δm > 0) from raising m; with require_descent the search ends there instead. (Where m is
// within a factor 2 of the largest double, δm = −2t m overflows and no trial passes: ‖F‖₂ above
// 9.5e153 for the engines on F, whose m = ‖F‖₂² overflows at 1.3e154 anyway.)
//
// The path is the caller's (a concept, as LBFGS++'s line search is a policy): the engines on F
// (newton, broyden) take detail::ResidualPath (square_system.hpp), x(t) = P(x + t d) projected
// onto their box ([Ber82]); the MHE its horizon's states projected onto theirs. A path has
//   bool exhausted()     the evaluation budget is spent: no further trial
//   bool move(double t)  to x(t); true when x(t) = x, a bound holding x in place: the search ends
//   double slope()       δm(t) at the last move (called only when the test needs it)
//   double merit()       m(x(t)), evaluating there; NaN where m is not defined (F not finite)
#include <cmath>
#include <concepts>

namespace nlobs {

template <typename Path>
concept LineSearchPath = requires(Path& path, double t) {
  { path.exhausted() } -> std::convertible_to<bool>;
  { path.move(t) } -> std::convertible_to<bool>;
  { path.slope() } -> std::convertible_to<double>;
  { path.merit() } -> std::convertible_to<double>;
};

struct LineSearch {
  enum class Kind { kBacktracking, kFullStep };
  Kind kind = Kind::kBacktracking;
  double sufficient_decrease = 1e-4;  // c ∈ (0, 1)
  double shrink = 0.5;                // ρ ∈ (0, 1)
  int max_backtracks = 30;            // shrinks after the first trial, ≥ 0
  bool require_descent = false;       // a trial with δm(t) ≥ 0 ends the search unaccepted

  // Throws InvalidInput "LineSearch::<field> = … is invalid: …" (options_validation.hpp). The
  // engines build theirs from options they validated (NewtonOptions::backtrack_factor is ρ);
  // a user's engine that takes one from its user calls this first.
  void validate() const;

  enum class Outcome {
    kAccepted,
    kHeld,        // the path's move left x where it was (a bound)
    kNotDescent,  // require_descent and δm(t) ≥ 0
    kNoDecrease,  // every trial refused
    kExhausted    // the path's budget ran out before a trial was accepted
  };
  struct Result {
    Outcome outcome = Outcome::kNoDecrease;
    double t = 0.0;      // the accepted trial's t; otherwise where the search stopped
    double merit = 0.0;  // m(x(t)) at the last trial evaluated
    int trials = 0;      // evaluations of m
    bool accepted() const { return outcome == Outcome::kAccepted; }
  };

  // Searches from t₀ where m(x) = merit0; the path is left at the last trial.
  template <LineSearchPath Path>
  Result search(Path& path, double t0, double merit0) const {
    Result r;
    r.t = t0;
    for (int k = 0; k <= (kind == Kind::kFullStep ? 0 : max_backtracks); ++k) {
      if (path.exhausted()) {
        r.outcome = Outcome::kExhausted;
        return r;
      }
      if (path.move(r.t)) {
        r.outcome = Outcome::kHeld;
        return r;
      }
      if (kind == Kind::kFullStep) {
        r.merit = path.merit();
        ++r.trials;
        r.outcome = std::isnan(r.merit) ? Outcome::kNoDecrease : Outcome::kAccepted;
        return r;
      }
      const double slope = path.slope();
      if (require_descent && !(slope < 0.0)) {
        r.outcome = Outcome::kNotDescent;
        return r;
      }
      r.merit = path.merit();
      ++r.trials;
      const double allowed = merit0 + sufficient_decrease * slope;
      // (A NaN, m undefined or δm, fails the test.)
      if (r.merit <= (merit0 < allowed ? merit0 : allowed)) {
        r.outcome = Outcome::kAccepted;
        return r;
      }
      r.t *= shrink;
    }
    r.outcome = Outcome::kNoDecrease;
    return r;
  }
};

}  // namespace nlobs
