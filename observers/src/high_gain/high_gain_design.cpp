#include "nlobs/observers/high_gain/high_gain_design.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <cmath>
#include <sstream>

#include "nlobs/solvers/status.hpp"

namespace nlobs {

Eigen::VectorXd hurwitz_coefficients(const std::vector<double>& poles) {
  Eigen::VectorXd c = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(poles.size()) + 1);
  c[0] = 1.0;  // ascending powers
  for (size_t j = 0; j < poles.size(); ++j) {
    const double p = poles[j];
    if (!(p < 0.0) || !std::isfinite(p)) {
      std::ostringstream os;
      os << "HighGainOptions::poles must be finite negative real roots (Hurwitz) (got " << p << ")";
      throw InvalidInput(os.str());
    }
    for (Eigen::Index k = static_cast<Eigen::Index>(j) + 1; k > 0; --k) c[k] = c[k - 1] - p * c[k];
    c[0] = -p * c[0];
  }
  return c.head(c.size() - 1);  // the leading 1 dropped
}

Eigen::VectorXcd polynomial_roots(const Eigen::VectorXd& l) {
  const Eigen::Index N = l.size();
  Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(N, N);
  companion.bottomLeftCorner(N - 1, N - 1).setIdentity();
  companion.col(N - 1) = -l;
  return Eigen::EigenSolver<Eigen::MatrixXd>(companion, false).eigenvalues();
}

double smallest_singular_value(const Eigen::MatrixXd& m) {
  if (m.size() == 0) return 0.0;
  const Eigen::VectorXd sv = Eigen::JacobiSVD<Eigen::MatrixXd>(m).singularValues();
  return sv[sv.size() - 1];
}

}  // namespace nlobs
