#pragma once
// User functions are any callable on Eigen vectors, in either of two shapes:
//   void f(const Eigen::Matrix<T, N, 1>& x, Eigen::Matrix<T, M, 1>& out)   (writes out)
//   Eigen::Matrix<T, M, 1> f(const Eigen::Matrix<T, N, 1>& x)            (returns)
// The first shape never allocates, even for dynamic sizes.
#include <concepts>
#include <utility>

namespace nlobs::detail {

// F may be a mutable callable (a lambda holding scratch space), hence the non-const F&.
template <typename F, typename In, typename Out>
void invoke_map(F& f, const In& x, Out& out) {
  if constexpr (std::invocable<F&, const In&, Out&>) {
    f(x, out);
  } else {
    static_assert(std::invocable<F&, const In&>,
                  "nlobs: a user function must be callable as f(x, out) or out = f(x)");
    out = f(x);
  }
}

}  // namespace nlobs::detail
