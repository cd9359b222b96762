#pragma once
// A root problem F(x) = 0 at run-time size that carries a sparse Jacobian, for the engines'
// sparse path (NewtonEngine with NewtonOptions::linear_solver; docs/solvers.md):
//   sparse_autodiff_problem(f, x)        f generic in its scalar type; its pattern detected by
//                                        evaluating f once at x on SparsityTracer scalars
//                                        (a branch on x is refused: declare the pattern then)
//   sparse_autodiff_problem(f, pattern)  the same with a declared pattern
//   sparse_difference_problem(f, pattern) f on doubles; J by coloured forward differences
// J is compressed by a column colouring: one AD pass of 8 directions (or one evaluation of f) per
// 8 colours (per colour), [CPR74]. The pattern gets the whole diagonal (a structural entry, zero
// where F_i does not depend on x_i: ILU(0) and Jacobi then still fail on the zero, named). The
// problem keeps the dense Jacobian of the AD path too, for the engines that have no sparse path
// yet. Coloured differences step forward (+h) whatever a box says: near a bound where F is not
// defined outside, use the AD form.
#include <memory>
#include <utility>

#include "nlobs/solvers/problem.hpp"
#include "nlobs/solvers/sparse/compressed_jacobian.hpp"

namespace nlobs {

namespace detail {
// `pattern` with every diagonal entry of its square part.
inline SparsityPattern with_diagonal(const SparsityPattern& pattern) {
  SparsityPattern out;
  out.rows = pattern.rows;
  out.cols = pattern.cols;
  out.row_start.assign(static_cast<std::size_t>(pattern.rows) + 1, 0);
  out.columns.reserve(pattern.columns.size() + static_cast<std::size_t>(pattern.rows));
  for (Index i = 0; i < pattern.rows; ++i) {
    bool placed = i >= pattern.cols;  // no diagonal entry in a row below the square part
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

template <typename Evaluate>
SparseJacobianSource sparse_source(const CompressedJacobian& compressed, Evaluate evaluate,
                                   int evaluations) {
  return SparseJacobianSource{std::make_shared<const SparsityPattern>(compressed.pattern()),
                              std::move(evaluate), evaluations};
}
}  // namespace detail

template <typename F>
RootProblem<> sparse_autodiff_problem(F f, SparsityPattern pattern) {
  CompressedJacobian compressed(detail::with_diagonal(pattern));
  const Index n = pattern.cols, m = pattern.rows;
  auto evaluate = [compressed, f](const Vector<Dynamic>& x, const Vector<Dynamic>&,
                                  SparseJacobian& jac) mutable {
    compressed.autodiff(f, x, jac);
    return 0;
  };
  SparseJacobianSource source = detail::sparse_source(compressed, std::move(evaluate), 0);
  return RootProblem<>::with_autodiff(std::move(f), n, m).with_sparse_jacobian(std::move(source));
}

// The pattern found at x (m outputs; default: square).
template <typename F>
RootProblem<> sparse_autodiff_problem(F f, const Vector<Dynamic>& x, Index m = -1) {
  SparsityPattern pattern = detect_sparsity(f, x, m < 0 ? x.size() : m);
  return sparse_autodiff_problem(std::move(f), std::move(pattern));
}

template <typename F>
RootProblem<> sparse_difference_problem(F f, SparsityPattern pattern) {
  CompressedJacobian compressed(detail::with_diagonal(pattern));
  const Index n = pattern.cols, m = pattern.rows;
  const int evaluations = compressed.difference_evaluations();
  auto evaluate = [compressed, f](const Vector<Dynamic>& x, const Vector<Dynamic>& fx,
                                  SparseJacobian& jac) mutable {
    return compressed.differences(f, x, fx, jac);
  };
  SparseJacobianSource source = detail::sparse_source(compressed, std::move(evaluate), evaluations);
  return RootProblem<>::from_map(std::move(f), n, m).with_sparse_jacobian(std::move(source));
}

}  // namespace nlobs
