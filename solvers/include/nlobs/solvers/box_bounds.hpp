#pragma once
// Box bounds lower ≤ x ≤ upper for the bounded engines (Ceres, NLopt): one validation, one
// message format. An empty vector means "no bound on that side".
#include <sstream>
#include <string_view>

#include "nlobs/solvers/status.hpp"
#include "nlobs/solvers/types.hpp"

namespace nlobs::detail {

// lower[i] ≤ upper[i] where both are given; sizes agree. Throws InvalidInput naming `owner`.
inline void validate_box(std::string_view owner, const Eigen::VectorXd& lower,
                         const Eigen::VectorXd& upper) {
  if (lower.size() > 0 && upper.size() > 0 && lower.size() != upper.size()) {
    std::ostringstream os;
    os << owner << ": lower_bounds and upper_bounds differ in size (" << lower.size() << " vs "
       << upper.size() << ")";
    throw InvalidInput(os.str());
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

}  // namespace nlobs::detail
