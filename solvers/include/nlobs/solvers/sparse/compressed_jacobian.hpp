#pragma once
// A sparse Jacobian from a few evaluations: with a column colouring of its pattern, one
// directional derivative J·d_c per colour c, d_c = Σ_{colour(j) = c} e_j, holds every entry of
// the columns of colour c (no two share a row), [CPR74]. By forward-mode AD (ceres::Jet,
// kJetStride colours per evaluation of F: ⌈colours / 8⌉ evaluations — one for a tridiagonal or
// 5-point-stencil Jacobian, where the dense AD Jacobian takes ⌈n / 8⌉) or by forward differences
// (one evaluation of F per colour instead of n).
//
// J is an Eigen::SparseMatrix<double, RowMajor> with exactly the pattern's structure (shape()
// sets it once); evaluations write its values in place and allocate nothing. (Eigen's sparse
// module is only declared here, so that problem.hpp can carry a compressed Jacobian cheaply: a
// caller that reads J includes nlobs/solvers/sparse/sparse_jacobian.hpp.) The pattern must
// hold every entry F has: an entry it misses is added, unseen, into an entry of the same row and
// colour. missing_entry() finds such an entry.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>

#include "nlobs/common/invalid_input.hpp"
#include "nlobs/solvers/autodiff.hpp"
#include "nlobs/solvers/callable.hpp"
#include "nlobs/solvers/sparse/column_colouring.hpp"
#include "nlobs/solvers/sparse/sparse_jacobian_source.hpp"
#include "nlobs/solvers/sparse/sparsity_pattern.hpp"

namespace nlobs {

class CompressedJacobian {
 public:
  // Colours the pattern (column_colouring.hpp); throws InvalidInput for a pattern with more
  // entries than J's int indices hold (src/compressed_jacobian.cpp).
  explicit CompressedJacobian(SparsityPattern pattern);

  const SparsityPattern& pattern() const { return pattern_; }
  const ColumnColouring& colouring() const { return colouring_; }
  // Evaluations of F per Jacobian: by AD, by differences.
  int autodiff_passes() const { return (colouring_.colours + kJetStride - 1) / kJetStride; }
  int difference_evaluations() const { return colouring_.colours; }

  // J sized and structured as the pattern (values zero) once, or when J was used elsewhere;
  // returns J's value array (src/compressed_jacobian.cpp).
  double* shape(SparseJacobian& jac) const;

  // J = ∂f/∂x at x by forward-mode AD, f generic in its scalar type (either shape of
  // callable.hpp) with pattern().rows outputs.
  template <typename F>
  void autodiff(F& f, const Vector<Dynamic>& x, SparseJacobian& jac) {
    using Jet = ceres::Jet<double, kJetStride>;
    check_size(x);
    double* values = shape(jac);
    xj_.resize(x.size());
    fj_.resize(pattern_.rows);
    for (int first = 0; first < colouring_.colours; first += kJetStride) {
      for (Index j = 0; j < x.size(); ++j) {
        xj_[j] = Jet(x[j]);
        const int lane = colouring_.colour[j] - first;
        if (lane >= 0 && lane < kJetStride) xj_[j].v[lane] = 1.0;
      }
      detail::invoke_map(f, xj_, fj_);
      check_output(fj_.size());
      for (Index i = 0; i < pattern_.rows; ++i) {
        for (Index k = pattern_.row_start[i]; k < pattern_.row_start[i + 1]; ++k) {
          const int lane = colouring_.colour[pattern_.columns[k]] - first;
          if (lane >= 0 && lane < kJetStride) values[k] = fj_[i].v[lane];
        }
      }
    }
  }

  // J ≈ ∂f/∂x at x by forward differences, f0 = f(x): column j's step h_j = √ε · max(1, |x_j|)
  // (made exact in binary), all columns of a colour at once. f as for autodiff, on doubles.
  // Returns the evaluations of f it made (difference_evaluations()).
  template <typename F>
  int differences(F& f, const Vector<Dynamic>& x, const Vector<Dynamic>& f0, SparseJacobian& jac) {
    check_size(x);
    check_output(f0.size());
    double* values = shape(jac);
    xt_ = x;
    ft_.resize(pattern_.rows);
    const double root_eps = std::sqrt(std::numeric_limits<double>::epsilon());
    for (int c = 0; c < colouring_.colours; ++c) {
      for (Index j = 0; j < x.size(); ++j) {
        if (colouring_.colour[j] == c) xt_[j] = x[j] + root_eps * std::max(1.0, std::abs(x[j]));
      }
      detail::invoke_map(f, xt_, ft_);
      check_output(ft_.size());
      for (Index j = 0; j < x.size(); ++j) {
        if (colouring_.colour[j] != c) continue;
        const double h = xt_[j] - x[j];
        for (Index e = columns_.start[j]; e < columns_.start[j + 1]; ++e) {
          const Index i = columns_.rows[e];
          values[columns_.positions[e]] = (ft_[i] - f0[i]) / h;
        }
        xt_[j] = x[j];
      }
    }
    return colouring_.colours;
  }

 private:
  void check_size(const Vector<Dynamic>& x) const {
    if (x.size() != pattern_.cols) {
      throw InvalidInput("CompressedJacobian: x has " + std::to_string(x.size()) +
                         " components, the pattern " + std::to_string(pattern_.cols) + " columns");
    }
  }
  void check_output(Index m) const {
    if (m != pattern_.rows) {
      throw InvalidInput("CompressedJacobian: F returned " + std::to_string(m) +
                         " values, the pattern has " + std::to_string(pattern_.rows) + " rows");
    }
  }

  SparsityPattern pattern_;
  PatternColumns columns_;
  ColumnColouring colouring_;
  Vector<Dynamic, ceres::Jet<double, kJetStride>> xj_, fj_;
  Vector<Dynamic> xt_, ft_;
};

namespace detail {
// The sparse Jacobian of f by compressed AD (f generic in its scalar type) or coloured forward
// differences (f on doubles), on `pattern` with its whole diagonal when square: a structural
// entry, zero where F_i does not depend on x_i (ILU(0) and Jacobi then still fail on the zero,
// named).
template <typename F>
SparseJacobianSource autodiff_jacobian_source(F f, const SparsityPattern& pattern) {
  CompressedJacobian compressed(with_diagonal(pattern));
  auto structure = std::make_shared<const SparsityPattern>(compressed.pattern());
  return SparseJacobianSource{
      std::move(structure),
      [compressed = std::move(compressed), f = std::move(f)](
          const Vector<Dynamic>& x, const Vector<Dynamic>&, SparseJacobian& jac) mutable {
        compressed.autodiff(f, x, jac);
        return 0;
      },
      0};
}
template <typename F>
SparseJacobianSource difference_jacobian_source(F f, const SparsityPattern& pattern) {
  CompressedJacobian compressed(with_diagonal(pattern));
  auto structure = std::make_shared<const SparsityPattern>(compressed.pattern());
  const int evaluations = compressed.difference_evaluations();
  return SparseJacobianSource{
      std::move(structure),
      [compressed = std::move(compressed), f = std::move(f)](
          const Vector<Dynamic>& x, const Vector<Dynamic>& fx, SparseJacobian& jac) mutable {
        return compressed.differences(f, x, fx, jac);
      },
      evaluations};
}
}  // namespace detail

// The first entry (row, column) that f — generic — has and `declared` lacks, found by
// detecting f's pattern at x (detect_sparsity: throws where f branches on x); nullopt when
// declared holds them all. For a test of a declared pattern, or a debug build's check.
template <typename F>
std::optional<std::pair<Index, Index>> missing_entry(F& f, const Vector<Dynamic>& x,
                                                     const SparsityPattern& declared) {
  const SparsityPattern found = detect_sparsity(f, x, declared.rows);
  if (found.rows != declared.rows || found.cols != declared.cols) {
    throw InvalidInput("missing_entry: F is " + std::to_string(found.rows) + "x" +
                       std::to_string(found.cols) + ", the declared pattern " +
                       std::to_string(declared.rows) + "x" + std::to_string(declared.cols));
  }
  for (Index i = 0; i < found.rows; ++i) {
    for (Index k = found.row_start[i]; k < found.row_start[i + 1]; ++k) {
      if (!declared.contains(i, found.columns[k])) return std::pair{i, found.columns[k]};
    }
  }
  return std::nullopt;
}

}  // namespace nlobs
