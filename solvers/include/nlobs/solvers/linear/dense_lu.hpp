#pragma once
// J x = b by LU with partial pivoting of J made dense: O(n²) memory, O(n³) per setup. The
// reference the other solvers are tested against, and the right choice below a few hundred
// unknowns or for a Jacobian with no structure.
#include <Eigen/LU>
#include <sstream>
#include <string>

#include "nlobs/solvers/linear/linear_solver.hpp"

namespace nlobs {

class DenseLuSolver final : public LinearSolver {
 public:
  // n above this is refused (n² doubles: 1.6 GB at the limit): a sparse solver's job.
  static constexpr Index kLargestSize = 14142;

  std::string_view name() const override { return "dense-lu"; }
  bool iterative() const override { return false; }

  LinearStatus setup(const SparseJacobian& jac) override {
    ++stats_.setups;
    if (const LinearStatus s = check_matrix(jac); s != LinearStatus::kSolved) return s;
    if (jac.rows() > kLargestSize) {
      return fail(LinearStatus::kInvalidInput,
                  "a dense " + std::to_string(jac.rows()) + "x" + std::to_string(jac.rows()) +
                      " J is too large (n > " + std::to_string(kLargestSize) +
                      "): use a sparse solver");
    }
    if (const LinearStatus s = equilibrate_rows(jac); s != LinearStatus::kSolved) return s;
    dense_ = jac;
    dense_ = row_scale_.asDiagonal() * dense_;
    lu_.compute(dense_);
    Index column = 0;
    const double smallest = lu_.matrixLU().diagonal().cwiseAbs().minCoeff(&column);
    if (!(smallest > kSingularPivot)) {
      std::ostringstream os;
      os << "J is singular: pivot " << smallest << " in column " << column
         << " of the LU factor of the row-equilibrated J";
      return fail(LinearStatus::kSingular, os.str());
    }
    size_ = jac.rows();
    return succeed();
  }

  LinearStatus solve(const Vector<Dynamic>& b, Vector<Dynamic>& x, double) override {
    ++stats_.solves;
    if (const LinearStatus s = check_right_hand_side(b); s != LinearStatus::kSolved) return s;
    rhs_ = row_scale_.cwiseProduct(b);  // before x is written: x may be b
    x = lu_.solve(rhs_);
    if (!x.allFinite()) return fail(LinearStatus::kSingular, "the solution is not finite");
    return succeed();
  }

 private:
  Matrix<Dynamic, Dynamic> dense_;
  Vector<Dynamic> rhs_;
  Eigen::PartialPivLU<Matrix<Dynamic, Dynamic>> lu_;
};

}  // namespace nlobs
