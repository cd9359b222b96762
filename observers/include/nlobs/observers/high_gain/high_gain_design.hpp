#pragma once
// The high-gain observer's design arithmetic that does not depend on the model, compiled once
// (src/high_gain/high_gain_design.cpp): the gain polynomial from its roots and back, and
// σ_min(∂q_N/∂x).
#include <Eigen/Core>
#include <vector>

namespace nlobs {

// [l_0, …, l_{N−1}] of Π (s − p_j). Throws InvalidInput for a root that is not < 0.
Eigen::VectorXd hurwitz_coefficients(const std::vector<double>& poles);

// The roots of s^N + l_{N−1}s^{N−1} + … + l_0 (eigenvalues of the companion matrix).
Eigen::VectorXcd polynomial_roots(const Eigen::VectorXd& l);

// The smallest singular value of m (0 for an empty matrix).
double smallest_singular_value(const Eigen::MatrixXd& m);

}  // namespace nlobs
