#pragma once
// ADOL-C's taped scalar as an Eigen scalar, so that models written for Eigen vectors of any T
// can be recorded on an ADOL-C tape (Eigen's "custom scalar types" recipe).
#include <adolc/adouble.h>

#include <Eigen/Core>

namespace Eigen {
template <>
struct NumTraits<adouble> : NumTraits<double> {
  using Real = adouble;
  using NonInteger = adouble;
  using Nested = adouble;
  using Literal = adouble;
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
}  // namespace Eigen
