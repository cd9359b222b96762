#pragma once
// Box bounds lower ≤ x ≤ upper, each bound closed or strict (lower < x: KINSOL's constraints
// ±2, a concentration c > 0, a log's argument): one validation and one message format for every
// bounded engine (Engine::set_bounds; CeresOptions and NloptOptions carry closed bounds as
// fields), and the projection the Newton-type engines take their steps through:
//   closed side:  P(x)_i = min(max(x_i, lower_i), upper_i);
//   strict side:  a step from x⁰ that would reach or cross lower_i stops at
//                 lower_i + (1 − τ)(x⁰_i − lower_i), τ = 0.99 — the fraction-to-the-boundary
//                 rule of interior-point methods [WB06, eq. (8)] —, and stays at x⁰_i when that
//                 room is below 1e-6 of the step (the bound holds the component).
// An empty vector means "no bound on that side"; ±inf entries mean no bound on that component.
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>

#include "nlobs/solvers/status.hpp"
#include "nlobs/solvers/types.hpp"

namespace nlobs {

// Which bounds of a side are strict, one flag per bound; empty: every bound of that side closed.
using StrictBounds = Eigen::Array<bool, Eigen::Dynamic, 1>;

struct BoxBounds {
  Eigen::VectorXd lower{}, upper{};
  // lower_i < x_i where strict_lower[i] (of lower's size), x_i < upper_i where strict_upper[i].
  StrictBounds strict_lower{}, strict_upper{};
  bool empty() const { return lower.size() == 0 && upper.size() == 0; }
  bool any_strict() const { return strict_lower.any() || strict_upper.any(); }
};

namespace detail {

// No NaN, no lower = +inf or upper = −inf (an empty box), lower[i] ≤ upper[i] where both are
// given, sizes agree. Throws InvalidInput naming `owner`.
inline void validate_box(std::string_view owner, const Eigen::VectorXd& lower,
                         const Eigen::VectorXd& upper) {
  if (lower.size() > 0 && upper.size() > 0 && lower.size() != upper.size()) {
    std::ostringstream os;
    os << owner << ": lower_bounds and upper_bounds differ in size (" << lower.size() << " vs "
       << upper.size() << ")";
    throw InvalidInput(os.str());
  }
  auto fail = [owner](const char* side, Index i, double value, const char* why) {
    std::ostringstream os;
    os << owner << ": " << side << "_bounds[" << i << "] = " << value << " " << why;
    throw InvalidInput(os.str());
  };
  for (Index i = 0; i < lower.size(); ++i) {
    if (std::isnan(lower[i])) fail("lower", i, lower[i], "is not a number");
    if (lower[i] == std::numeric_limits<double>::infinity()) fail("lower", i, lower[i], "is +inf");
  }
  for (Index i = 0; i < upper.size(); ++i) {
    if (std::isnan(upper[i])) fail("upper", i, upper[i], "is not a number");
    if (upper[i] == -std::numeric_limits<double>::infinity()) fail("upper", i, upper[i], "is -inf");
  }
  for (Index i = 0; i < std::min(lower.size(), upper.size()); ++i) {
    if (!(lower[i] <= upper[i])) {
      std::ostringstream os;
      os << owner << ": lower_bounds[" << i << "] = " << lower[i] << " > upper_bounds[" << i
         << "] = " << upper[i];
      throw InvalidInput(os.str());
    }
  }
}

// The closed checks above, and each strict side of its bound's size, never given without that
// bound, never on a component with lower = upper (no x would satisfy it).
inline void validate_box(std::string_view owner, const BoxBounds& b) {
  validate_box(owner, b.lower, b.upper);
  auto check_side = [owner](const StrictBounds& strict, const Eigen::VectorXd& side,
                            const char* name) {
    if (strict.size() == 0 || strict.size() == side.size()) return;
    std::ostringstream os;
    os << owner << ": strict_" << name << " has " << strict.size() << " flags, " << name
       << "_bounds " << side.size() << " bounds (one flag per bound)";
    throw InvalidInput(os.str());
  };
  check_side(b.strict_lower, b.lower, "lower");
  check_side(b.strict_upper, b.upper, "upper");
  for (Index i = 0; i < std::min(b.lower.size(), b.upper.size()); ++i) {
    const bool strict = (b.strict_lower.size() > 0 && b.strict_lower[i]) ||
                        (b.strict_upper.size() > 0 && b.strict_upper[i]);
    if (strict && b.lower[i] == b.upper[i]) {
      std::ostringstream os;
      os << owner << ": lower_bounds[" << i << "] = upper_bounds[" << i << "] = " << b.lower[i]
         << " with a strict side: no x satisfies it";
      throw InvalidInput(os.str());
    }
  }
}

// v moved into the box: a closed side clamps to its bound, a strict side to the nearest double
// inside it (a point computed in other variables — a scaled solve's D_u⁻¹ x̃ — that rounding put
// on or past the bound).
inline double into_box(double v, double lower, double upper, bool strict_lower, bool strict_upper) {
  if (v < lower || (strict_lower && v == lower)) {
    return strict_lower ? std::nextafter(lower, std::numeric_limits<double>::infinity()) : lower;
  }
  if (v > upper || (strict_upper && v == upper)) {
    return strict_upper ? std::nextafter(upper, -std::numeric_limits<double>::infinity()) : upper;
  }
  return v;
}

// The box fits the problem's dimension and holds x0. Throws InvalidInput naming the component.
template <int N>
void require_inside_box(std::string_view owner, const Eigen::VectorXd& lower,
                        const Eigen::VectorXd& upper, const Vector<N>& x) {
  auto check = [&](const Eigen::VectorXd& b, bool is_lower) {
    if (b.size() == 0) return;
    if (b.size() != x.size()) {
      std::ostringstream os;
      os << owner << ": " << (is_lower ? "lower" : "upper") << "_bounds has size " << b.size()
         << ", the problem has dimension " << x.size();
      throw InvalidInput(os.str());
    }
    for (Index i = 0; i < x.size(); ++i) {
      if (is_lower ? x[i] < b[i] : x[i] > b[i]) {
        std::ostringstream os;
        os << owner << ": initial guess x0[" << i << "] = " << x[i] << " lies outside the box ("
           << (is_lower ? "lower" : "upper") << " bound " << b[i] << ")";
        throw InvalidInput(os.str());
      }
    }
  };
  check(lower, true);
  check(upper, false);
}

// As above, and x0 strictly inside each strict side.
template <int N>
void require_inside_box(std::string_view owner, const BoxBounds& b, const Vector<N>& x) {
  require_inside_box<N>(owner, b.lower, b.upper, x);
  auto check = [&](const StrictBounds& strict, const Eigen::VectorXd& side, bool is_lower) {
    for (Index i = 0; i < strict.size(); ++i) {
      if (strict[i] && x[i] == side[i]) {
        std::ostringstream os;
        os << owner << ": initial guess x0[" << i << "] = " << x[i] << " lies on its strict "
           << (is_lower ? "lower" : "upper") << " bound (" << (is_lower ? "lower < x" : "x < upper")
           << " required)";
        throw InvalidInput(os.str());
      }
    }
  };
  check(b.strict_lower, b.lower, true);
  check(b.strict_upper, b.upper, false);
}

// The bounds of one solve as vectors of the problem's size (±inf where a side is absent), for
// engines that keep every iterate — and every finite-difference point — inside the box. Sized
// in start(): at a fixed N nothing allocates.
// What an engine asks the box to block: a step in x, or only a direction (a gradient).
enum class BoxMove { kStep, kDirection };

template <int N>
class Box {
 public:
  // Checks the bounds' sizes and that x0 lies inside (InvalidInput naming owner), then copies.
  void start(std::string_view owner, const BoxBounds& bounds, const Vector<N>& x0) {
    require_inside_box<N>(owner, bounds, x0);
    set(bounds, x0.size());
  }
  // Copies bounds (of size n or empty, as validate_box checked) for n unknowns.
  void set(const BoxBounds& bounds, Index n) {
    const double inf = std::numeric_limits<double>::infinity();
    if constexpr (N == Dynamic) {
      lower_.resize(n), upper_.resize(n), strict_lower_.resize(n), strict_upper_.resize(n);
    }
    if (bounds.lower.size() > 0) {
      lower_ = bounds.lower;
    } else {
      lower_.setConstant(-inf);
    }
    if (bounds.upper.size() > 0) {
      upper_ = bounds.upper;
    } else {
      upper_.setConstant(inf);
    }
    strict_lower_.setConstant(false);
    strict_upper_.setConstant(false);
    if (bounds.strict_lower.size() == n) strict_lower_ = bounds.strict_lower;
    if (bounds.strict_upper.size() == n) strict_upper_ = bounds.strict_upper;
    active_ = lower_.array().isFinite().any() || upper_.array().isFinite().any();
  }
  // Some component has a finite bound: steps are projected.
  bool active() const { return active_; }
  const Vector<N>& lower() const { return lower_; }
  const Vector<N>& upper() const { return upper_; }

  // τ of the fraction-to-the-boundary rule on a strict side [WB06, eq. (8)].
  static constexpr double kFractionToBoundary = 0.99;
  // A component whose room to a bound is at most kNegligible of the step is held by it.
  static constexpr double kNegligible = 1e-6;

  // The i-th component of a step from `from` (inside the box) to `trial`, projected (above).
  double projected(Index i, double trial, double from) const {
    const double lo = lower_[i], hi = upper_[i];
    const bool below = trial < lo || (strict_lower_[i] && trial == lo);
    const bool above = trial > hi || (strict_upper_[i] && trial == hi);
    if (!below && !above) return trial;  // NaN too: the engine's own test sees it
    const double bound = below ? lo : hi;
    if (!(below ? strict_lower_[i] : strict_upper_[i])) return bound;
    const double room = std::abs(from - bound);
    if (room <= kNegligible * std::abs(trial - from)) return from;
    const double stop = bound + (1.0 - kFractionToBoundary) * (from - bound);
    return stop != bound ? stop : std::nextafter(bound, from);
  }

  // trial ← its projection for a step from `from`; true when a component moved.
  bool project(Vector<N>& trial, const Vector<N>& from) const {
    if (!active_) return false;
    bool moved = false;
    for (Index i = 0; i < trial.size(); ++i) {
      const double c = projected(i, trial[i], from[i]);
      moved = moved || c != trial[i];
      trial[i] = c;
    }
    return moved;
  }

  // The distance x_j may move down (up) for a finite-difference point: to a closed bound all of
  // it, to a strict one half of it (the point stays strictly inside).
  double room_below(Index j, double x) const {
    return strict_lower_[j] ? 0.5 * (x - lower_[j]) : x - lower_[j];
  }
  double room_above(Index j, double x) const {
    return strict_upper_[j] ? 0.5 * (upper_[j] - x) : upper_[j] - x;
  }

  // v moved into the box (into_box): for a point computed in other variables.
  double clamp(Index i, double v) const {
    return into_box(v, lower_[i], upper_[i], strict_lower_[i], strict_upper_[i]);
  }

  // Whether v lies on (or past) a strict bound of component j: no point to evaluate.
  bool on_strict_bound(Index j, double v) const {
    return (strict_lower_[j] && v <= lower_[j]) || (strict_upper_[j] && v >= upper_[j]);
  }

  // Whether x_i sits on a closed bound that d_i points out of: the active set of a projected
  // method (a strict bound is never reached, so it holds nothing here).
  bool on_closed_bound_against(Index i, double x, double d) const {
    if (d < 0.0) return !strict_lower_[i] && x <= lower_[i];
    if (d > 0.0) return !strict_upper_[i] && x >= upper_[i];
    return false;
  }

  // Whether a bound holds x_i against a move d_i: a closed bound as above; a strict one it points
  // to when the room left is negligible, at most kNegligible · max(1, |bound|, |s_i|) with s_i the
  // step's own length (0 when d is only a direction, such as a gradient, whose entries are not
  // lengths of x). Asked only once an engine is stuck, so a tiny-scale x near a strict bound at
  // worst ends blocked_by_bound instead of stagnated, both failures.
  bool held(Index i, double x, double d, double step_length) const {
    if (on_closed_bound_against(i, x, d)) return true;
    const bool to_strict = d < 0.0 ? strict_lower_[i] : d > 0.0 && strict_upper_[i];
    if (!to_strict) return false;
    const double bound = d < 0.0 ? lower_[i] : upper_[i];
    const double room = std::abs(x - bound);
    return room <= kNegligible * std::max({1.0, std::abs(bound), step_length});
  }

  // Whether the box stops x from moving along d (a step in x, or only a direction): some
  // component is held (above) and what the box lets through, P(x + d) − x, is at most
  // kNegligible of ‖d‖∞. Then the first held component; else none.
  std::optional<Index> blocking(const Vector<N>& x, const Vector<N>& d, BoxMove move) const {
    if (!active_) return std::nullopt;
    const double d_max = d.template lpNorm<Eigen::Infinity>();
    std::optional<Index> first_held;
    double through = 0.0;
    for (Index i = 0; i < x.size(); ++i) {
      if (held(i, x[i], d[i], move == BoxMove::kStep ? std::abs(d[i]) : 0.0)) {
        if (!first_held) first_held = i;
      } else {
        through = std::max(through, std::abs(projected(i, x[i] + d[i], x[i]) - x[i]));
      }
    }
    if (first_held && through <= kNegligible * d_max) return first_held;
    return std::nullopt;
  }

  // The message of Status::kBlockedByBound for component i.
  std::string blocked_message(Index i, const Vector<N>& x, double residual_norm,
                              std::string_view direction) const {
    const bool lower = x[i] - lower_[i] <= upper_[i] - x[i];
    const double bound = lower ? lower_[i] : upper_[i];
    std::ostringstream os;
    os << "x[" << i << "] = " << std::setprecision(std::numeric_limits<double>::max_digits10)
       << x[i] << std::setprecision(6);
    if (lower ? strict_lower_[i] : strict_upper_[i]) {
      os << " is held next to its strict " << (lower ? "lower" : "upper") << " bound " << bound
         << " (" << std::abs(x[i] - bound) << " from it): " << direction << " points past it";
    } else {
      os << " is held at its " << (lower ? "lower" : "upper") << " bound: " << direction
         << " points out of the box there";
    }
    os << " (|F| = " << residual_norm << ")";
    return os.str();
  }

 private:
  Vector<N> lower_ = zero_vector<N>(), upper_ = zero_vector<N>();
  Eigen::Array<bool, N, 1> strict_lower_{}, strict_upper_{};
  bool active_ = false;
};

}  // namespace detail
}  // namespace nlobs
