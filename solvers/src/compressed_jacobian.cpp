#include "nlobs/solvers/sparse/compressed_jacobian.hpp"

#include <algorithm>
#include <limits>
#include <string>
#include <utility>

#include "nlobs/solvers/sparse/sparse_jacobian.hpp"

namespace nlobs {

CompressedJacobian::CompressedJacobian(SparsityPattern pattern)
    : pattern_(std::move(pattern)), columns_(pattern_), colouring_(colour_columns(pattern_)) {
  if (pattern_.nonzeros() > std::numeric_limits<int>::max()) {
    throw InvalidInput("CompressedJacobian: " + std::to_string(pattern_.nonzeros()) +
                       " entries exceed the sparse matrix's index type");
  }
}

double* CompressedJacobian::shape(SparseJacobian& jac) const {
  if (jac.rows() == pattern_.rows && jac.cols() == pattern_.cols &&
      jac.nonZeros() == pattern_.nonzeros() && jac.isCompressed()) {
    return jac.valuePtr();
  }
  jac.resize(pattern_.rows, pattern_.cols);
  jac.resizeNonZeros(pattern_.nonzeros());
  std::copy(pattern_.row_start.begin(), pattern_.row_start.end(), jac.outerIndexPtr());
  std::copy(pattern_.columns.begin(), pattern_.columns.end(), jac.innerIndexPtr());
  std::fill_n(jac.valuePtr(), pattern_.nonzeros(), 0.0);
  return jac.valuePtr();
}

}  // namespace nlobs
