#pragma once
// Vector and matrix aliases shared by every layer. `N` is a compile-time size or
// Eigen::Dynamic; fixed sizes keep every solve free of heap allocation.
#include <Eigen/Core>

namespace nlobs {

inline constexpr int Dynamic = Eigen::Dynamic;
using Index = Eigen::Index;

template <int N = Dynamic, typename Scalar = double>
using Vector = Eigen::Matrix<Scalar, N, 1>;

template <int Rows = Dynamic, int Cols = Dynamic, typename Scalar = double>
using Matrix = Eigen::Matrix<Scalar, Rows, Cols>;

// A zero vector of size N (empty for dynamic N): initialises workspace members, so that
// copying a not-yet-started accelerator or engine never reads uninitialised memory.
template <int N>
Vector<N> zero_vector() {
  if constexpr (N == Dynamic) {
    return Vector<N>();
  } else {
    return Vector<N>::Zero();
  }
}

}  // namespace nlobs
