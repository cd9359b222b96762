#pragma once
// χ² quantiles for the observers' consistency checks (a least-squares window's cost against its
// declared noise): Boost.Math's, compiled once in observers/src/core/chi_squared.cpp, so that
// no observer header includes Boost.Math's distributions.
namespace nlobs {

// x with P(χ²(dof) ≤ x) = probability. Throws InvalidInput unless dof is finite and > 0 and
// probability is in (0, 1).
double chi_squared_quantile(double dof, double probability);

}  // namespace nlobs
