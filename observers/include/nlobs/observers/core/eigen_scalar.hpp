#pragma once
// Eigen's NumTraits for a scalar type that behaves like double (an AD or interval type), per
// Eigen's "custom scalar types" recipe: specialise as
//   template <> struct Eigen::NumTraits<MyScalar> : nlobs::DoubleLikeNumTraits<MyScalar> {};
#include <Eigen/Core>

namespace nlobs {

template <typename Scalar>
struct DoubleLikeNumTraits : Eigen::NumTraits<double> {
  using Real = Scalar;
  using NonInteger = Scalar;
  using Nested = Scalar;
  using Literal = Scalar;
  enum {
    IsComplex = 0,
    IsInteger = 0,
    IsSigned = 1,
    RequireInitialization = 1,
    ReadCost = 1,
    AddCost = 3,
    MulCost = 3
  };
};

}  // namespace nlobs
