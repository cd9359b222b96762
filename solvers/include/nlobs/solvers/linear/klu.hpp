#pragma once
// J x = b by SuiteSparse's KLU [DN10], the sparse LU for circuit and PDE Jacobians that KINSOL
// and SUNDIALS use (SUNLinSol_KLU): a BTF and AMD ordering, left-looking LU with threshold
// partial pivoting that prefers the diagonal (KLU's tol = 0.001), rows scaled by their largest
// entry. As KINSOL does, a Jacobian with the pattern of the last one is refactored with the
// last pivot order (klu_refactor, no search), and factored afresh when that order has gone bad
// (KLU's pivot ratio min|U_kk| / max|U_kk| below ε^(2/3)).
//
// J's compressed rows are handed to KLU as the compressed columns of Jᵀ, and J x = b is solved
// as (Jᵀ)ᵀ x = b (klu_tsolve): no copy of J's structure, only of its values, rows equilibrated
// (LinearSolver::kSingularPivot); KLU's own row scaling of Jᵀ then equilibrates J's columns.
#include <klu.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <type_traits>
#include <vector>

#include "nlobs/solvers/linear/equilibrated_rows.hpp"
#include "nlobs/solvers/linear/linear_solver.hpp"

namespace nlobs {

class KluSolver final : public LinearSolver {
 public:
  static_assert(std::is_same_v<SparseJacobian::StorageIndex, int>, "KLU takes int indices");

  KluSolver() { klu_defaults(&common_); }
  KluSolver(const KluSolver&) = delete;
  KluSolver& operator=(const KluSolver&) = delete;
  ~KluSolver() override { release(); }

  std::string_view name() const override { return "klu"; }
  bool iterative() const override { return false; }
  // Setups that refactored with the last pivot order (the rest factored afresh).
  int refactorizations() const { return refactorizations_; }

  LinearStatus setup(const SparseJacobian& jac) override {
    ++stats_.setups;
    if (const LinearStatus s = check_matrix(jac); s != LinearStatus::kSolved) return s;
    const SparseJacobian& source = rows_.compressed(jac);
    const int n = static_cast<int>(source.rows());
    // Rows of J equilibrated here; KLU's own scaling of Jᵀ's rows then scales J's columns.
    if (const LinearStatus s = equilibrate_rows(source); s != LinearStatus::kSolved) return s;
    rows_.scale(source, row_scale_);
    double* values = rows_.values();
    const bool same_pattern = rows_.same_pattern_else_keep(source) && symbolic_ != nullptr;
    int* start = rows_.starts();
    int* index = rows_.indices();
    if (!same_pattern) {
      release();
      n_ = n;
      symbolic_ = klu_analyze(n, start, index, &common_);
      if (symbolic_ == nullptr) return klu_failure("klu_analyze");
    }
    if (numeric_ != nullptr) {
      const double bad_order = std::pow(std::numeric_limits<double>::epsilon(), 2.0 / 3.0);
      if (klu_refactor(start, index, values, symbolic_, numeric_, &common_) == 1 &&
          klu_rcond(symbolic_, numeric_, &common_) == 1 && common_.rcond > bad_order) {
        ++refactorizations_;
        size_ = n;
        return succeed();
      }
      klu_free_numeric(&numeric_, &common_);
    }
    numeric_ = klu_factor(start, index, values, symbolic_, &common_);
    if (numeric_ == nullptr) return klu_failure("klu_factor");
    if (klu_rcond(symbolic_, numeric_, &common_) != 1) return klu_failure("klu_rcond");
    if (!(common_.rcond > kSingularPivot)) {
      std::ostringstream os;
      os << "J is singular: KLU's pivot ratio min|U_kk| / max|U_kk| = " << common_.rcond;
      klu_free_numeric(&numeric_, &common_);
      return fail(LinearStatus::kSingular, os.str());
    }
    size_ = n;
    return succeed();
  }

  LinearStatus solve(const Vector<Dynamic>& b, Vector<Dynamic>& x, double) override {
    ++stats_.solves;
    if (const LinearStatus s = check_right_hand_side(b); s != LinearStatus::kSolved) return s;
    x = row_scale_.cwiseProduct(b);  // KLU solves in place
    if (klu_tsolve(symbolic_, numeric_, n_, 1, x.data(), &common_) != 1) {
      return klu_failure("klu_tsolve");
    }
    if (!x.allFinite()) {
      return fail(LinearStatus::kSingular, "the solution is not finite (J numerically singular)");
    }
    return succeed();
  }

 private:
  LinearStatus klu_failure(const char* call) {
    std::ostringstream os;
    if (common_.status == KLU_SINGULAR) {
      // KLU factors Jᵀ: its zero column of U is J's row.
      os << "J is singular (" << call << ": zero pivot, row " << common_.singular_col << " of J)";
      size_ = -1;
      return fail(LinearStatus::kSingular, os.str());
    }
    os << call << " failed with KLU status " << common_.status
       << (common_.status == KLU_OUT_OF_MEMORY ? " (out of memory)" : "");
    size_ = -1;
    return fail(LinearStatus::kPackageFailure, os.str());
  }
  void release() {
    if (numeric_ != nullptr) klu_free_numeric(&numeric_, &common_);
    if (symbolic_ != nullptr) klu_free_symbolic(&symbolic_, &common_);
  }

  klu_common common_{};
  klu_symbolic* symbolic_ = nullptr;
  klu_numeric* numeric_ = nullptr;
  int n_ = 0, refactorizations_ = 0;
  detail::EquilibratedRows rows_;  // J's pattern and its values, rows equilibrated
};

}  // namespace nlobs
