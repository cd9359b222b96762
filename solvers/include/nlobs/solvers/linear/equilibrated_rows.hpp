#pragma once
// What KLU and UMFPACK both take from J before they factor it (klu.hpp, umfpack.hpp): J's
// compressed rows (a compressed copy where J has gaps: the libraries read the arrays as they are),
// its values with each row scaled by LinearSolver::equilibrate_rows' row_scale, and the pattern
// of the last symbolic analysis, kept so that a Jacobian of the same pattern reuses it.
#include <algorithm>
#include <vector>

#include "nlobs/solvers/sparse/sparse_jacobian.hpp"
#include "nlobs/solvers/types.hpp"

namespace nlobs::detail {

class EquilibratedRows {
 public:
  // J itself when compressed, else a compressed copy kept here.
  const SparseJacobian& compressed(const SparseJacobian& jac) {
    if (jac.isCompressed()) return jac;
    copy_ = jac;
    copy_.makeCompressed();
    return copy_;
  }
  // values()[k] = row_scale[i] · J's k-th value, k in row i.
  void scale(const SparseJacobian& source, const Vector<Dynamic>& row_scale) {
    const int* start = source.outerIndexPtr();
    values_.resize(static_cast<std::size_t>(source.nonZeros()));
    for (Index i = 0; i < source.rows(); ++i) {
      for (Index k = start[i]; k < start[i + 1]; ++k) {
        values_[static_cast<std::size_t>(k)] = row_scale[i] * source.valuePtr()[k];
      }
    }
  }
  double* values() { return values_.data(); }
  // Whether `source` has the pattern kept by the last keep_pattern(); if not, keeps its pattern
  // (the caller analyses it afresh).
  bool same_pattern_else_keep(const SparseJacobian& source) {
    const int* start = source.outerIndexPtr();
    const int* index = source.innerIndexPtr();
    const Index n = source.rows(), nonzeros = source.nonZeros();
    if (starts_.size() == static_cast<std::size_t>(n) + 1 &&
        indices_.size() == static_cast<std::size_t>(nonzeros) &&
        std::equal(start, start + n + 1, starts_.begin()) &&
        std::equal(index, index + nonzeros, indices_.begin())) {
      return true;
    }
    starts_.assign(start, start + n + 1);
    indices_.assign(index, index + nonzeros);
    return false;
  }
  // The kept pattern (J's row starts and columns: Jᵀ's compressed columns).
  int* starts() { return starts_.data(); }
  int* indices() { return indices_.data(); }

 private:
  SparseJacobian copy_;  // a copy only of an uncompressed J
  std::vector<double> values_;
  std::vector<int> starts_, indices_;
};

}  // namespace nlobs::detail
