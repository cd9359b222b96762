#pragma once
// No acceleration: the next point is G(x) (Picard, [MGFF23]: w ← G(w)).
#include <string_view>

#include "nlobs/solvers/types.hpp"

namespace nlobs {

template <int N = Dynamic>
class PicardStep {
 public:
  static constexpr bool kPicardSteps = true;  // step ratios estimate G's contraction factor
  std::string_view name() const { return "picard"; }
  void start(const Vector<N>&) {}
  bool propose(const Vector<N>&, const Vector<N>& gx, Vector<N>& next, Vector<N>& estimate) {
    next = gx;
    estimate = gx;
    return true;
  }
};

}  // namespace nlobs
