#pragma once
// J x = b for a band J (J_ij = 0 unless −lower ≤ j − i ≤ upper) by LU with partial pivoting in
// band storage, the algorithm of LAPACK's dgbtf2/dgbtrs [ABB99, §4.3] (KINSOL's band solver is
// the same method): O((2·lower + upper + 1)·n) memory and O(lower·(lower + upper)·n) work per
// setup, O((2·lower + upper)·n) per solve. Row interchanges widen U's band to lower + upper.
//
// The widths are J's own (read from its pattern at each setup) or declared at construction; an
// entry outside a declared band is refused, not dropped. Rows are equilibrated first
// (LinearSolver::kSingularPivot).
#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "nlobs/common/invalid_input.hpp"
#include "nlobs/solvers/linear/linear_solver.hpp"

namespace nlobs {

class BandLuSolver final : public LinearSolver {
 public:
  // Widths read from J at each setup().
  BandLuSolver() = default;
  // Declared widths (≥ 0): J must lie inside them.
  BandLuSolver(Index lower, Index upper) : declared_(std::pair{lower, upper}) {
    if (lower < 0 || upper < 0) {
      throw InvalidInput("BandLuSolver: bandwidths lower = " + std::to_string(lower) +
                         ", upper = " + std::to_string(upper) + " must be >= 0");
    }
  }

  std::string_view name() const override { return "band-lu"; }
  bool iterative() const override { return false; }
  Index lower() const { return lower_; }
  Index upper() const { return upper_; }

  LinearStatus setup(const SparseJacobian& jac) override {
    ++stats_.setups;
    if (const LinearStatus s = check_matrix(jac); s != LinearStatus::kSolved) return s;
    if (const LinearStatus s = equilibrate_rows(jac); s != LinearStatus::kSolved) return s;
    n_ = jac.rows();
    Index lower = 0, upper = 0;
    for (Index i = 0; i < n_; ++i) {
      for (SparseJacobian::InnerIterator it(jac, i); it; ++it) {
        const Index j = it.col();
        if (declared_ && (i - j > declared_->first || j - i > declared_->second)) {
          std::ostringstream os;
          os << "J(" << i << ", " << j << ") lies outside the declared band (lower "
             << declared_->first << ", upper " << declared_->second << ")";
          return fail(LinearStatus::kInvalidInput, os.str());
        }
        lower = std::max(lower, i - j);
        upper = std::max(upper, j - i);
      }
    }
    if (declared_) std::tie(lower, upper) = *declared_;
    lower_ = std::min(lower, n_ - 1);
    upper_ = std::min(upper, n_ - 1);
    const Index diagonal = lower_ + upper_;  // row of J_jj in band storage
    rows_ = 2 * lower_ + upper_ + 1;
    if (static_cast<double>(rows_) * static_cast<double>(n_) > 2e8) {  // 1.6 GB
      std::ostringstream os;
      os << "the band (lower " << lower_ << ", upper " << upper_ << ") of a " << n_ << "x" << n_
         << " J needs " << rows_ << " x " << n_ << " values: use a sparse solver";
      return fail(LinearStatus::kInvalidInput, os.str());
    }
    band_.assign(static_cast<std::size_t>(rows_ * n_), 0.0);
    pivots_.resize(static_cast<std::size_t>(n_));
    for (Index i = 0; i < n_; ++i) {
      for (SparseJacobian::InnerIterator it(jac, i); it; ++it) {
        at(diagonal + i - it.col(), it.col()) = row_scale_[i] * it.value();
      }
    }
    // dgbtf2: column j's pivot among rows j … j + lower; U's last touched column in `reach`.
    Index reach = 0;
    for (Index j = 0; j < n_; ++j) {
      const Index below = std::min(lower_, n_ - 1 - j);
      Index pivot = 0;
      for (Index p = 1; p <= below; ++p) {
        if (std::abs(at(diagonal + p, j)) > std::abs(at(diagonal + pivot, j))) pivot = p;
      }
      pivots_[static_cast<std::size_t>(j)] = j + pivot;
      const double value = at(diagonal + pivot, j);
      if (!(std::abs(value) > kSingularPivot)) {
        std::ostringstream os;
        os << "J is singular: pivot " << std::abs(value) << " in column " << j
           << " of the band LU factor of the row-equilibrated J";
        return fail(LinearStatus::kSingular, os.str());
      }
      reach = std::max(reach, std::min(j + upper_ + pivot, n_ - 1));
      if (pivot != 0) {
        for (Index c = j; c <= reach; ++c) {
          std::swap(at(diagonal + pivot - (c - j), c), at(diagonal - (c - j), c));
        }
      }
      for (Index r = 1; r <= below; ++r) at(diagonal + r, j) /= value;
      for (Index c = j + 1; c <= reach; ++c) {
        const double u = at(diagonal - (c - j), c);
        if (u == 0.0) continue;
        for (Index r = 1; r <= below; ++r) at(diagonal + r - (c - j), c) -= at(diagonal + r, j) * u;
      }
    }
    size_ = n_;
    return succeed();
  }

  LinearStatus solve(const Vector<Dynamic>& b, Vector<Dynamic>& x, double) override {
    ++stats_.solves;
    if (const LinearStatus s = check_right_hand_side(b); s != LinearStatus::kSolved) return s;
    const Index diagonal = lower_ + upper_;
    x = row_scale_.cwiseProduct(b);
    for (Index j = 0; j + 1 < n_; ++j) {  // L y = P D⁻¹ b
      const Index p = pivots_[static_cast<std::size_t>(j)];
      if (p != j) std::swap(x[p], x[j]);
      const Index below = std::min(lower_, n_ - 1 - j);
      for (Index r = 1; r <= below; ++r) x[j + r] -= at(diagonal + r, j) * x[j];
    }
    for (Index j = n_ - 1; j >= 0; --j) {  // U x = y, U of upper width lower + upper
      x[j] /= at(diagonal, j);
      for (Index i = std::max<Index>(0, j - diagonal); i < j; ++i) {
        x[i] -= at(diagonal + i - j, j) * x[j];
      }
    }
    if (!x.allFinite()) return fail(LinearStatus::kSingular, "the solution is not finite");
    return succeed();
  }

 private:
  // Band storage of LAPACK's dgbtrf, column-major: J_ij in row lower + upper + i − j of column j.
  double& at(Index row, Index column) {
    return band_[static_cast<std::size_t>(column * rows_ + row)];
  }

  std::optional<std::pair<Index, Index>> declared_;
  Index n_ = 0, lower_ = 0, upper_ = 0, rows_ = 0;
  std::vector<double> band_;
  std::vector<Index> pivots_;
};

}  // namespace nlobs
