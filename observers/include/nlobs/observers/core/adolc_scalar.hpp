#pragma once
// ADOL-C's taped scalar as an Eigen scalar, so that models written for Eigen vectors of any T
// can be recorded on an ADOL-C tape (Eigen's "custom scalar types" recipe).
#include <adolc/adouble.h>

#include <Eigen/Core>

#include "nlobs/observers/core/eigen_scalar.hpp"

namespace Eigen {
template <>
struct NumTraits<adouble> : nlobs::DoubleLikeNumTraits<adouble> {};
}  // namespace Eigen
