#pragma once
// A column colouring of a sparsity pattern: columns of one colour share no row, so one
// evaluation of J·d with d = Σ_{colour(j) = c} e_j recovers every entry of those columns
// (Curtis, Powell and Reid [CPR74]; Gebremedhin, Manne and Pothen [GMP05] call it a distance-2
// colouring of the column intersection graph). Greedy in Brélaz's DSATUR order [Bré79]: next
// the column whose neighbours (the columns it shares a row with) already use the most colours,
// given the first colour none of them uses. Measured in tests/test_sparse_jacobian.cpp: 3
// colours for a tridiagonal pattern, lower + upper + 1 for a band, 5 for the 2-D 5-point
// stencil — each the fewest possible (a row with k entries needs k colours); the natural column
// order gives 7 on the stencil, and is kept where it already reaches the longest row (bands).
// Cost O(Σ_i nnz(row i)² log n) time, O(n) memory.
#include <vector>

#include "nlobs/solvers/sparse/sparsity_pattern.hpp"

namespace nlobs {

struct ColumnColouring {
  std::vector<int> colour;  // of each column, 0 .. colours − 1
  int colours = 0;
};

// The columns of `p`, column by column: for each, the rows it has entries in (transposed
// pattern; CSC structure) and where each entry lies in p.columns (its index in a CSR value
// array).
struct PatternColumns {
  std::vector<Index> start;      // cols + 1 offsets
  std::vector<Index> rows;       // the rows of each column, sorted
  std::vector<Index> positions;  // of each (row, column) entry in p.columns
  explicit PatternColumns(const SparsityPattern& p);
};

// (src/column_colouring.cpp)
ColumnColouring colour_columns(const SparsityPattern& p);

// Whether no two columns of one colour share a row (and every column has a colour in range).
bool valid_colouring(const SparsityPattern& p, const ColumnColouring& c);

}  // namespace nlobs
