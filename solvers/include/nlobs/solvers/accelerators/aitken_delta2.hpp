#pragma once
// Component-wise Aitken Δ² transform ([MGFF23]):
//   z = x_l − (x_{l+1} − x_l)² / (x_{l+2} − 2x_{l+1} + x_l),
// evaluated in the equivalent form anchored at the newest point,
//   z = x_{l+2} − (x_{l+2} − x_{l+1})² / (x_{l+2} − 2x_{l+1} + x_l),
// which loses less to cancellation near convergence. Where the second difference is zero or at
// rounding level (Remark 8: equal consecutive values) the component keeps x_{l+2}: no
// division by zero, no NaN.
#include <algorithm>
#include <cmath>
#include <limits>

#include "nlobs/solvers/types.hpp"

namespace nlobs {

template <int N>
void aitken_delta2(const Vector<N>& a, const Vector<N>& b, const Vector<N>& c, Vector<N>& z) {
  constexpr double kEps = std::numeric_limits<double>::epsilon();
  for (Index i = 0; i < c.size(); ++i) {
    const double last = c[i] - b[i];
    const double curvature = last - (b[i] - a[i]);  // Δ²x
    const double scale = std::max({std::abs(a[i]), std::abs(b[i]), std::abs(c[i])});
    z[i] = std::abs(curvature) > 8.0 * kEps * scale && curvature != 0.0
               ? c[i] - last * last / curvature
               : c[i];
  }
}

}  // namespace nlobs
