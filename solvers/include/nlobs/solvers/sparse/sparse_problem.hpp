#pragma once
// A root problem F(x) = 0 at run-time size that carries a sparse Jacobian, for the engines'
// sparse path (NewtonEngine with NewtonOptions::linear_solver; docs/solvers.md):
//   sparse_autodiff_problem(f, x)        f generic in its scalar type; its pattern detected by
//                                        evaluating f once at x on SparsityTracer scalars
//                                        (a branch on x is refused: declare the pattern then)
//   sparse_autodiff_problem(f, pattern)  the same with a declared pattern
//   sparse_difference_problem(f, pattern) f on doubles; J by coloured forward differences
// J is compressed by a column colouring: one AD pass of 8 directions (or one evaluation of f) per
// 8 colours (per colour), [CPR74]. A square pattern gets the whole diagonal (a structural entry,
// zero where F_i does not depend on x_i: ILU(0) and Jacobi then still fail on the zero, named). The
// problem keeps the dense Jacobian of the AD path too, for the engines that have no sparse path
// yet. Coloured differences step forward (+h) whatever a box says: near a bound where F is not
// defined outside, use the AD form.
#include <utility>

#include "nlobs/solvers/problem.hpp"
#include "nlobs/solvers/sparse/compressed_jacobian.hpp"

namespace nlobs {

template <typename F>
RootProblem<> sparse_autodiff_problem(F f, const SparsityPattern& pattern) {
  SparseJacobianSource source = detail::autodiff_jacobian_source(f, pattern);
  return RootProblem<>::with_dense_autodiff(std::move(f), pattern.cols, pattern.rows)
      .with_sparse_jacobian(std::move(source));
}

// The pattern found at x (m outputs; default: square).
template <typename F>
RootProblem<> sparse_autodiff_problem(F f, const Vector<Dynamic>& x, Index m = -1) {
  SparsityPattern pattern = detect_sparsity(f, x, m < 0 ? x.size() : m);
  return sparse_autodiff_problem(std::move(f), std::move(pattern));
}

template <typename F>
RootProblem<> sparse_difference_problem(F f, const SparsityPattern& pattern) {
  SparseJacobianSource source = detail::difference_jacobian_source(f, pattern);
  return RootProblem<>::from_map(std::move(f), pattern.cols, pattern.rows)
      .with_sparse_jacobian(std::move(source));
}

}  // namespace nlobs
