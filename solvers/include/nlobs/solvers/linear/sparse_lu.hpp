#pragma once
// J x = b by Eigen's supernodal SparseLU with a COLAMD column ordering [DGL99]: the sparse
// direct solver with no dependency beyond Eigen. The symbolic analysis (ordering, elimination
// tree) is redone only when J's pattern changes. An exactly singular J (a zero pivot, a
// structurally empty column) is reported with SparseLU's own message, a numerically singular one
// by its pivots (rows equilibrated first, LinearSolver::kSingularPivot). Its solve allocates (two
// temporaries for the permutations).
#include <Eigen/SparseLU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <type_traits>
#include <vector>

#include "nlobs/solvers/linear/linear_solver.hpp"

namespace nlobs {

class SparseLuSolver final : public LinearSolver {
 public:
  std::string_view name() const override { return "sparse-lu"; }
  bool iterative() const override { return false; }

  LinearStatus setup(const SparseJacobian& jac) override {
    ++stats_.setups;
    if (const LinearStatus s = check_matrix(jac); s != LinearStatus::kSolved) return s;
    if (const LinearStatus s = equilibrate_rows(jac); s != LinearStatus::kSolved) return s;
    scaled_ = row_scale_.asDiagonal() * jac;  // compressed, whatever jac's storage
    scaled_.makeCompressed();
    const Index n = jac.rows(), nonzeros = scaled_.nonZeros();
    const bool same_pattern =
        analysed_ && column_major_.rows() == n && static_cast<Index>(columns_.size()) == nonzeros &&
        std::equal(scaled_.outerIndexPtr(), scaled_.outerIndexPtr() + n + 1, row_start_.begin()) &&
        std::equal(scaled_.innerIndexPtr(), scaled_.innerIndexPtr() + nonzeros, columns_.begin());
    column_major_ = scaled_;
    if (!same_pattern) {
      row_start_.assign(scaled_.outerIndexPtr(), scaled_.outerIndexPtr() + n + 1);
      columns_.assign(scaled_.innerIndexPtr(), scaled_.innerIndexPtr() + nonzeros);
      lu_.analyzePattern(column_major_);
      analysed_ = true;
    }
    lu_.factorize(column_major_);
    if (lu_.info() != Eigen::Success) {
      return fail(LinearStatus::kSingular,
                  "J is singular (SparseLU: " + lu_.lastErrorMessage() + ")");
    }
    if (const double smallest = smallest_pivot(); !(smallest > kSingularPivot)) {
      std::ostringstream os;
      os << "J is singular: pivot " << smallest
         << " in SparseLU's factor of the row-equilibrated J";
      return fail(LinearStatus::kSingular, os.str());
    }
    size_ = n;
    return succeed();
  }

  LinearStatus solve(const Vector<Dynamic>& b, Vector<Dynamic>& x, double) override {
    ++stats_.solves;
    if (const LinearStatus s = check_right_hand_side(b); s != LinearStatus::kSolved) return s;
    rhs_ = row_scale_.cwiseProduct(b);  // before x is written: x may be b
    x = lu_.solve(rhs_);
    if (lu_.info() != Eigen::Success || !x.allFinite()) {
      return fail(LinearStatus::kSingular, "the solution is not finite (J numerically singular)");
    }
    return succeed();
  }

 private:
  // min |U_kk|. U's diagonal lives in the supernodes of L's storage, reached as
  // SparseLU::absDeterminant reaches it, through Eigen 3.4's public
  // SparseLUMatrixLReturnType::m_mapL.
  double smallest_pivot() const {
    const auto& supernodes = lu_.matrixL().m_mapL;
    using Supernodes = std::remove_cvref_t<decltype(supernodes)>;
    double smallest = std::numeric_limits<double>::infinity();
    for (Index j = 0; j < supernodes.cols(); ++j) {
      double pivot = 0.0;
      for (typename Supernodes::InnerIterator it(supernodes, j); it; ++it) {
        if (it.index() == j) {
          pivot = std::abs(it.value());
          break;
        }
      }
      smallest = std::min(smallest, pivot);
    }
    return smallest;
  }

  SparseJacobian scaled_;
  Vector<Dynamic> rhs_;
  Eigen::SparseMatrix<double, Eigen::ColMajor> column_major_;
  Eigen::SparseLU<Eigen::SparseMatrix<double, Eigen::ColMajor>, Eigen::COLAMDOrdering<int>> lu_;
  bool analysed_ = false;
  std::vector<SparseJacobian::StorageIndex> row_start_, columns_;
};

}  // namespace nlobs
