#pragma once
// ρ(A) = max |λ_i(A)|: the local contraction factor of a fixed-point map at a point where A is
// its Jacobian (Picard converges near a fixed point p when ρ(∂G(p)) < 1, Ostrowski's theorem).
// Compiled once (the eigenvalue solver is a heavy header).
#include <Eigen/Core>

namespace nlobs {

// NaN when A is not square, empty, or not finite.
double spectral_radius(const Eigen::Ref<const Eigen::MatrixXd>& a);

}  // namespace nlobs
