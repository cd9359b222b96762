#pragma once
// Box bounds lower ≤ x ≤ upper: one validation and one message format for every bounded engine
// (Engine::set_bounds; CeresOptions and NloptOptions carry them as fields), and the projection
// P(x) = min(max(x, lower), upper) the Newton-type engines take their steps through.
// An empty vector means "no bound on that side"; ±inf entries mean no bound on that component.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>

#include "nlobs/solvers/status.hpp"
#include "nlobs/solvers/types.hpp"

namespace nlobs {

struct BoxBounds {
  Eigen::VectorXd lower{}, upper{};
  bool empty() const { return lower.size() == 0 && upper.size() == 0; }
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

// The bounds of one solve as vectors of the problem's size (±inf where a side is absent), for
// engines that keep every iterate — and every finite-difference point — inside the box. Sized
// in start(): at a fixed N nothing allocates.
template <int N>
class Box {
 public:
  // Checks the bounds' sizes and that x0 lies inside (InvalidInput naming owner), then copies.
  void start(std::string_view owner, const BoxBounds& bounds, const Vector<N>& x0) {
    require_inside_box<N>(owner, bounds.lower, bounds.upper, x0);
    const Index n = x0.size();
    const double inf = std::numeric_limits<double>::infinity();
    if constexpr (N == Dynamic) lower_.resize(n), upper_.resize(n);
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
    active_ = lower_.array().isFinite().any() || upper_.array().isFinite().any();
  }
  // Some component has a finite bound: steps are projected.
  bool active() const { return active_; }
  const Vector<N>& lower() const { return lower_; }
  const Vector<N>& upper() const { return upper_; }

  // x ← P(x); true when a component moved.
  bool project(Vector<N>& x) const {
    if (!active_) return false;
    bool moved = false;
    for (Index i = 0; i < x.size(); ++i) {
      const double c = std::clamp(x[i], lower_[i], upper_[i]);
      moved = moved || c != x[i];
      x[i] = c;
    }
    return moved;
  }

  // Whether the box stops x from moving along d: some component is held (at its lower bound
  // with d_i < 0, or at its upper bound with d_i > 0) and what the box lets through,
  // P(x + d) − x, is at most kNegligible of ‖d‖∞. Then the first held component; else none.
  static constexpr double kNegligible = 1e-6;
  std::optional<Index> blocking(const Vector<N>& x, const Vector<N>& d) const {
    if (!active_) return std::nullopt;
    std::optional<Index> held;
    double through = 0.0;
    for (Index i = 0; i < x.size(); ++i) {
      if ((x[i] <= lower_[i] && d[i] < 0.0) || (x[i] >= upper_[i] && d[i] > 0.0)) {
        if (!held) held = i;
      } else {
        through = std::max(through, std::abs(std::clamp(x[i] + d[i], lower_[i], upper_[i]) - x[i]));
      }
    }
    if (held && through <= kNegligible * d.template lpNorm<Eigen::Infinity>()) return held;
    return std::nullopt;
  }

  // The message of Status::kBlockedByBound for component i.
  std::string blocked_message(Index i, const Vector<N>& x, double residual_norm,
                              std::string_view direction) const {
    std::ostringstream os;
    os << "x[" << i << "] = " << x[i] << " is held at its "
       << (x[i] <= lower_[i] ? "lower" : "upper") << " bound: " << direction
       << " points out of the box there (|F| = " << residual_norm << ")";
    return os.str();
  }

 private:
  Vector<N> lower_ = zero_vector<N>(), upper_ = zero_vector<N>();
  bool active_ = false;
};

}  // namespace detail
}  // namespace nlobs
