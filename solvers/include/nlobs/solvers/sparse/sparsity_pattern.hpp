#pragma once
// The sparsity pattern of an m×n Jacobian (which entries may be non-zero), stored by rows
// (compressed sparse row: the columns of row i are columns[row_start[i] .. row_start[i+1]),
// sorted), and how to find it: declared (from_entries, band) or detected by evaluating a generic
// F once on SparsityTracer inputs (detect_sparsity).
#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "nlobs/common/invalid_input.hpp"
#include "nlobs/solvers/callable.hpp"
#include "nlobs/solvers/sparse/sparsity_tracer.hpp"
#include "nlobs/solvers/types.hpp"

namespace nlobs {

struct SparsityPattern {
  Index rows = 0, cols = 0;
  std::vector<Index> row_start{0};  // rows + 1 offsets into columns
  std::vector<Index> columns;       // each row's columns, sorted, no repeats

  Index nonzeros() const { return static_cast<Index>(columns.size()); }
  double density() const {
    return rows * cols == 0 ? 0.0
                            : static_cast<double>(nonzeros()) /
                                  (static_cast<double>(rows) * static_cast<double>(cols));
  }
  bool contains(Index i, Index j) const {
    const auto begin = columns.begin() + row_start[i], end = columns.begin() + row_start[i + 1];
    return std::binary_search(begin, end, j);
  }
  friend bool operator==(const SparsityPattern&, const SparsityPattern&) = default;

  // From (row, column) entries in any order, repeats allowed. Throws InvalidInput naming an entry
  // outside rows × cols.
  static SparsityPattern from_entries(Index rows, Index cols,
                                      std::vector<std::pair<Index, Index>> entries) {
    if (rows < 0 || cols < 0) {
      throw InvalidInput("SparsityPattern: " + std::to_string(rows) + "x" + std::to_string(cols) +
                         " is not a matrix size");
    }
    for (const auto& [i, j] : entries) {
      if (i < 0 || i >= rows || j < 0 || j >= cols) {
        throw InvalidInput("SparsityPattern: entry (" + std::to_string(i) + ", " +
                           std::to_string(j) + ") lies outside the " + std::to_string(rows) + "x" +
                           std::to_string(cols) + " matrix");
      }
    }
    std::sort(entries.begin(), entries.end());
    entries.erase(std::unique(entries.begin(), entries.end()), entries.end());
    SparsityPattern p;
    p.rows = rows;
    p.cols = cols;
    p.row_start.assign(static_cast<std::size_t>(rows) + 1, 0);
    p.columns.reserve(entries.size());
    for (const auto& [i, j] : entries) {
      ++p.row_start[static_cast<std::size_t>(i) + 1];
      p.columns.push_back(j);
    }
    for (Index i = 0; i < rows; ++i) p.row_start[i + 1] += p.row_start[i];
    return p;
  }

  // The n×n band lower ≤ j − i … i − j ≤ upper: entries with −lower ≤ j − i ≤ upper. Throws
  // InvalidInput for a negative width or one of n or more.
  static SparsityPattern band(Index n, Index lower, Index upper) {
    for (const auto& [name, width] : {std::pair{"lower", lower}, std::pair{"upper", upper}}) {
      if (width < 0 || (n > 0 && width >= n)) {
        throw InvalidInput(std::string("SparsityPattern::band: ") + name + " bandwidth " +
                           std::to_string(width) +
                           " is out of range: must be in 0 .. n - 1 = " + std::to_string(n - 1));
      }
    }
    SparsityPattern p;
    p.rows = p.cols = n;
    p.row_start.assign(static_cast<std::size_t>(n) + 1, 0);
    for (Index i = 0; i < n; ++i) {
      for (Index j = std::max<Index>(0, i - lower); j <= std::min(n - 1, i + upper); ++j) {
        p.columns.push_back(j);
      }
      p.row_start[i + 1] = static_cast<Index>(p.columns.size());
    }
    return p;
  }
};

namespace detail {
// A square `pattern` with every diagonal entry; any other unchanged (src/sparsity_pattern.cpp).
SparsityPattern with_diagonal(const SparsityPattern& pattern);

// What one evaluation of f on SparsityTracer inputs found: the pattern, the comparisons of values
// that depend on x (branches), and whether the trace went past its limits (then the pattern is
// empty and meaningless).
struct SparsityTrace {
  SparsityPattern pattern;
  long branches = 0;
  bool exceeded = false;
};

// Evaluates f once at x on SparsityTracer inputs within `limits`; m as detect_sparsity's. The
// tracer's thread-local counters are reset on the way out, also when f throws.
template <typename F>
SparsityTrace trace_sparsity(F& f, const Vector<Dynamic>& x, Index m, SparsityTraceLimits limits) {
  struct Reset {
    ~Reset() {
      SparsityTracerBranches = 0;
      SparsityTracerLimits = SparsityTraceLimits{};
    }
  } reset;
  SparsityTracerBranches = 0;
  SparsityTracerLimits = limits;
  const Index n = x.size();
  Vector<Dynamic, SparsityTracer> traced(n);
  for (Index j = 0; j < n; ++j) traced[j] = SparsityTracer(x[j], j);
  Vector<Dynamic, SparsityTracer> out(m == Dynamic ? n : m);
  invoke_map(f, traced, out);
  SparsityTrace trace;
  trace.branches = SparsityTracerBranches;
  trace.exceeded = SparsityTracerLimits.exceeded;
  if (trace.exceeded) return trace;
  SparsityPattern& p = trace.pattern;
  p.rows = out.size();
  p.cols = n;
  p.row_start.assign(static_cast<std::size_t>(p.rows) + 1, 0);
  for (Index i = 0; i < p.rows; ++i) {
    const std::vector<Index>& row = out[i].inputs();
    p.columns.insert(p.columns.end(), row.begin(), row.end());
    p.row_start[i + 1] = static_cast<Index>(p.columns.size());
  }
  return trace;
}
}  // namespace detail

// The pattern of f: Rⁿ → Rᵐ, f generic in its scalar type (either shape of callable.hpp),
// from one evaluation at x on SparsityTracer inputs. m: f's output size (Dynamic: whatever f
// returns; for a writing f, n). Throws InvalidInput when f compared a value that depends on x (its
// pattern may change with x: declare it, or use a dense Jacobian) — naming how many comparisons.
template <typename F>
SparsityPattern detect_sparsity(F& f, const Vector<Dynamic>& x, Index m = Dynamic) {
  detail::SparsityTrace trace = detail::trace_sparsity(f, x, m, {});
  if (trace.branches > 0) {
    throw InvalidInput("detect_sparsity: F compared a value that depends on x (" +
                       std::to_string(trace.branches) +
                       " comparisons): its pattern may depend on x, and one evaluation sees "
                       "only the branch taken at this x; declare the pattern or use a dense "
                       "Jacobian");
  }
  return std::move(trace.pattern);
}

}  // namespace nlobs
