#include "nlobs/solvers/sparse/sparsity_pattern.hpp"

#include <algorithm>

#include "nlobs/solvers/sparse/pattern_bandwidths.hpp"

namespace nlobs {

PatternBandwidths pattern_bandwidths(const SparsityPattern& pattern) {
  PatternBandwidths out;
  for (Index i = 0; i < pattern.rows; ++i) {
    const auto first = static_cast<std::size_t>(pattern.row_start[static_cast<std::size_t>(i)]);
    const auto end = static_cast<std::size_t>(pattern.row_start[static_cast<std::size_t>(i) + 1]);
    if (first == end) continue;  // columns are sorted: the first and last bound the row
    out.lower = std::max(out.lower, i - pattern.columns[first]);
    out.upper = std::max(out.upper, pattern.columns[end - 1] - i);
  }
  return out;
}

}  // namespace nlobs

namespace nlobs::detail {

SparsityPattern with_diagonal(const SparsityPattern& pattern) {
  // A least-squares J (m > n) goes to the normal equations, where a structural zero on its
  // diagonal only adds fill to JᵀJ and colours: left as it is.
  if (pattern.rows != pattern.cols) return pattern;
  SparsityPattern out;
  out.rows = pattern.rows;
  out.cols = pattern.cols;
  out.row_start.assign(static_cast<std::size_t>(pattern.rows) + 1, 0);
  out.columns.reserve(pattern.columns.size() + static_cast<std::size_t>(pattern.rows));
  for (Index i = 0; i < pattern.rows; ++i) {
    bool placed = false;
    for (Index k = pattern.row_start[i]; k < pattern.row_start[i + 1]; ++k) {
      const Index j = pattern.columns[k];
      if (!placed && j >= i) {
        if (j != i) out.columns.push_back(i);
        placed = true;
      }
      out.columns.push_back(j);
    }
    if (!placed) out.columns.push_back(i);
    out.row_start[static_cast<std::size_t>(i) + 1] = static_cast<Index>(out.columns.size());
  }
  return out;
}

}  // namespace nlobs::detail
