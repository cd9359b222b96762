#pragma once
// The double inside a scalar of generic model code — what step-size control and Newton's method
// decide with, so that a move computed on AD scalars takes the same steps as on doubles and its
// derivative is that of the method with those steps ([HNW93] §II.4: step sizes are not
// differentiated). Written by shape, so that the models layer names no AD type:
//   double, float …              itself
//   ceres::Jet (and Jet of Jet)  .a
//   SparsityTracer, AutoDiffScalar  .value()
// Not for a taped scalar (ADOL-C's adouble): a decision taken on the value while taping would be
// replayed at every other x. Nothing in nlobs tapes a discrete model.
#include <type_traits>

namespace nlobs {

template <typename T>
double scalar_value(const T& v) {
  if constexpr (std::is_arithmetic_v<T>) {
    return static_cast<double>(v);
  } else if constexpr (requires { v.a; }) {
    return scalar_value(v.a);
  } else if constexpr (requires { v.value(); }) {
    return scalar_value(v.value());
  } else {
    static_assert(!sizeof(T), "scalar_value: a scalar with no value (.a, .value())");
  }
}

}  // namespace nlobs
