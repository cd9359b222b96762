#include "nlobs/solvers/spectral_radius.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>

namespace nlobs {

double spectral_radius(const Eigen::Ref<const Eigen::MatrixXd>& a) {
  if (a.rows() != a.cols() || a.size() == 0 || !a.allFinite()) return std::nan("");
  const Eigen::EigenSolver<Eigen::MatrixXd> eigen(a, /*computeEigenvectors=*/false);
  if (eigen.info() != Eigen::Success) return std::nan("");
  return eigen.eigenvalues().cwiseAbs().maxCoeff();
}

}  // namespace nlobs
