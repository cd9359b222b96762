#pragma once
// When RootProblem::with_autodiff (run-time size) gives the engines a sparse Jacobian it found
// itself, and how (docs/solvers.md, "Sparse Jacobians"). At the first point x an engine with a
// sparse path asks with, F is evaluated once on SparsityTracer scalars; the pattern found is
// used, compressed by a column colouring, when
//   m ≥ n ≥ kSmallestSize                       (below, the dense Jacobian costs next to nothing
//                                               and small problems keep their exact behaviour;
//                                               m > n: least squares, levenberg-marquardt's
//                                               sparse path),
//   F compares no value that depends on x       (a branch: the pattern may change with x),
//   no row of J has more than max(kRowFloor, n / kRowFraction) entries, and the trace copies at
//   most kBudgetPerUnknown · n indices in all   (dense rows: the dense path is cheaper, and the
//                                               trace stops early rather than cost O(n²)).
// Otherwise the engines use the dense AD Jacobian, as without detection; the problem's
// sparse_jacobian_note() says which rule decided (or that F threw while traced: declined too).
// with_dense_jacobian() switches detection off;
// sparse_autodiff_problem(f, pattern) declares a pattern instead (for F with branches).
#include <algorithm>
#include <optional>
#include <string>

#include "nlobs/solvers/sparse/compressed_jacobian.hpp"
#include "nlobs/solvers/sparse/sparse_jacobian_source.hpp"
#include "nlobs/solvers/sparse/sparsity_pattern.hpp"

namespace nlobs {

struct SparsityDetectionRule {
  static constexpr Index kSmallestSize = 100;
  static constexpr Index kRowFloor = 10;
  static constexpr Index kRowFraction = 10;
  static constexpr long long kBudgetPerUnknown = 10000;

  static Index largest_row(Index n) { return std::max(kRowFloor, n / kRowFraction); }
};

namespace detail {
// F's sparse Jacobian found at x by the rule above, or nullopt; `note` says what was decided.
template <typename F>
std::optional<SparseJacobianSource> detect_sparse_jacobian(F& f, const Vector<Dynamic>& x, Index m,
                                                           std::string& note) {
  using Rule = SparsityDetectionRule;
  const Index n = x.size();
  if (m < n) {
    note = "not detected: F is " + std::to_string(m) + "x" + std::to_string(n) +
           ", fewer residuals than unknowns: no engine has a sparse path for it";
    return std::nullopt;
  }
  if (n < Rule::kSmallestSize) {
    note = "not detected: n = " + std::to_string(n) + " is below " +
           std::to_string(Rule::kSmallestSize) + ", where the dense Jacobian is used";
    return std::nullopt;
  }
  SparsityTraceLimits limits;
  limits.largest_set = static_cast<std::size_t>(Rule::largest_row(n));
  limits.budget = Rule::kBudgetPerUnknown * static_cast<long long>(n);
  SparsityTrace trace = trace_sparsity(f, x, m, limits);
  if (trace.exceeded) {
    note = "not detected: a row of J has more than " + std::to_string(Rule::largest_row(n)) +
           " entries, or the trace copied more than " + std::to_string(limits.budget) +
           " indices: J is treated as dense";
    return std::nullopt;
  }
  if (trace.branches > 0) {
    note = "not detected: F compared a value that depends on x (" + std::to_string(trace.branches) +
           " comparisons), so its pattern may change with x; declare it "
           "(sparse_autodiff_problem(f, pattern)) for the sparse path";
    return std::nullopt;
  }
  SparseJacobianSource source = autodiff_jacobian_source(f, trace.pattern);
  note = "detected: " + std::to_string(source.pattern->nonzeros()) + " entries";
  return source;
}
}  // namespace detail

}  // namespace nlobs
