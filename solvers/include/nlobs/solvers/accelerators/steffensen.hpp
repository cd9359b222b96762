#pragma once
// Steffensen ([MGFF23] §3.2, eqs. 58–59): from p compute p1 = G(p), p2 = G(p1), restart from the
// Aitken value of (p, p1, p2). One iteration = one restart = two G evaluations.
#include <string_view>

#include "nlobs/solvers/accelerators/aitken_delta2.hpp"

namespace nlobs {

template <int N = Dynamic>
class SteffensenRestart {
 public:
  std::string_view name() const { return "steffensen"; }
  void start(const Vector<N>& x0) {
    p_.resize(x0.size());
    second_ = false;
  }
  bool propose(const Vector<N>& x, const Vector<N>& gx, Vector<N>& next, Vector<N>& estimate) {
    if (!second_) {  // x = p, gx = p1
      p_ = x;
      next = gx;
      second_ = true;
      return false;
    }
    aitken_delta2<N>(p_, x, gx, next);  // x = p1, gx = p2
    estimate = next;
    second_ = false;
    return true;
  }

 private:
  Vector<N> p_ = zero_vector<N>();
  bool second_ = false;
};

}  // namespace nlobs
