#pragma once
// Aitken engine ([MGFF23] §3.1): the Picard sequence x_{l+1} = G(x_l) runs unchanged; the
// engine's own sequence is its Δ² transform z_l = Aitken(x_l, x_{l+1}, x_{l+2}), which the stop
// criteria watch and the engine returns. One G evaluation per iteration after the first.
#include <string_view>

#include "nlobs/solvers/accelerators/aitken_delta2.hpp"

namespace nlobs {

template <int N = Dynamic>
class AitkenTransform {
 public:
  std::string_view name() const { return "aitken"; }
  void start(const Vector<N>& x0) {
    previous_.resize(x0.size());
    have_previous_ = false;
  }
  bool propose(const Vector<N>& x, const Vector<N>& gx, Vector<N>& next, Vector<N>& estimate) {
    next = gx;  // the Picard sequence continues
    if (!have_previous_) {
      previous_ = x;
      have_previous_ = true;
      return false;
    }
    aitken_delta2<N>(previous_, x, gx, estimate);
    previous_ = x;
    return true;
  }

 private:
  Vector<N> previous_ = zero_vector<N>();
  bool have_previous_ = false;
};

}  // namespace nlobs
