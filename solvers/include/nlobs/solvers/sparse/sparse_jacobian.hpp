#pragma once
// A Jacobian in compressed sparse row form: what CompressedJacobian fills and the linear solvers
// (linear/) take.
#include <Eigen/SparseCore>

namespace nlobs {

using SparseJacobian = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;

}  // namespace nlobs
