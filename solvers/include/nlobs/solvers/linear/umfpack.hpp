#pragma once
// J x = b by SuiteSparse's UMFPACK [Dav04], the unsymmetric multifrontal sparse LU (MATLAB's
// `\` for sparse square matrices): frontal matrices factored with dense kernels (BLAS 3), which
// is what pays on 2-D and 3-D grids, where the factors fill in and KLU's left-looking,
// kernel-free factorisation spends most of its time (Bratu at 10⁶ unknowns: one factorisation
// 7–11 s against KLU's 22–33 s). The symbolic analysis (column ordering, AMD by default, or
// METIS' nested dissection) is kept while J's pattern stays; every setup() factors afresh
// (UMFPACK has no refactorisation with the last pivots, as KLU has).
//
// As KluSolver: J's compressed rows are the compressed columns of Jᵀ, and J x = b is solved as
// (Jᵀ)ᵀ x = b (UMFPACK_At), rows of J equilibrated first (LinearSolver::kSingularPivot);
// UMFPACK's own scaling and its two steps of iterative refinement as its defaults have them.
#include <umfpack.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <type_traits>
#include <vector>

#include "nlobs/solvers/linear/equilibrated_rows.hpp"
#include "nlobs/solvers/linear/linear_solver.hpp"

namespace nlobs {

enum class UmfpackOrdering {
  kAmd,    // UMFPACK_ORDERING_AMD: AMD on Jᵀ J's or J + Jᵀ's pattern, UMFPACK's default
  kMetis,  // UMFPACK_ORDERING_METIS: METIS nested dissection (slower to analyse, less fill)
};

class UmfpackSolver final : public LinearSolver {
 public:
  static_assert(std::is_same_v<SparseJacobian::StorageIndex, int>, "umfpack_di takes int");

  explicit UmfpackSolver(UmfpackOrdering ordering = UmfpackOrdering::kAmd) {
    umfpack_di_defaults(control_.data());
    control_[UMFPACK_ORDERING] =
        ordering == UmfpackOrdering::kMetis ? UMFPACK_ORDERING_METIS : UMFPACK_ORDERING_AMD;
  }
  UmfpackSolver(const UmfpackSolver&) = delete;
  UmfpackSolver& operator=(const UmfpackSolver&) = delete;
  ~UmfpackSolver() override { release(); }

  std::string_view name() const override { return "umfpack"; }
  bool iterative() const override { return false; }
  // Setups that analysed a new pattern (the rest reused the last analysis).
  int symbolic_analyses() const { return symbolic_analyses_; }

  LinearStatus setup(const SparseJacobian& jac) override {
    ++stats_.setups;
    if (const LinearStatus s = check_matrix(jac); s != LinearStatus::kSolved) return s;
    const SparseJacobian& source = rows_.compressed(jac);
    const int n = static_cast<int>(source.rows());
    if (const LinearStatus s = equilibrate_rows(source); s != LinearStatus::kSolved) return s;
    rows_.scale(source, row_scale_);
    const bool same_pattern = rows_.same_pattern_else_keep(source) && symbolic_ != nullptr;
    if (numeric_ != nullptr) umfpack_di_free_numeric(&numeric_);
    if (!same_pattern) {
      release();
      const int status = umfpack_di_symbolic(n, n, rows_.starts(), rows_.indices(), rows_.values(),
                                             &symbolic_, control_.data(), info_.data());
      if (status < 0) return umfpack_failure("umfpack_di_symbolic", status);
      ++symbolic_analyses_;
      // The solve's workspace (umfpack_di_wsolve; 5n doubles with iterative refinement), here
      // rather than allocated by each solve as umfpack_di_solve would.
      int_workspace_.resize(static_cast<std::size_t>(n));
      workspace_.resize(5 * static_cast<std::size_t>(n));
    }
    const int status = umfpack_di_numeric(rows_.starts(), rows_.indices(), rows_.values(),
                                          symbolic_, &numeric_, control_.data(), info_.data());
    // umfpack_di_numeric returns OK, the singular warning, or an error (< 0).
    const double rcond = info_[UMFPACK_RCOND];
    if (status == UMFPACK_WARNING_singular_matrix || (status >= 0 && !(rcond > kSingularPivot))) {
      std::ostringstream os;
      os << "J is singular: UMFPACK's pivot ratio min|U_kk| / max|U_kk| = " << rcond;
      if (numeric_ != nullptr) umfpack_di_free_numeric(&numeric_);
      return fail(LinearStatus::kSingular, os.str());
    }
    if (status < 0) return umfpack_failure("umfpack_di_numeric", status);
    size_ = n;
    return succeed();
  }

  LinearStatus solve(const Vector<Dynamic>& b, Vector<Dynamic>& x, double) override {
    ++stats_.solves;
    if (const LinearStatus s = check_right_hand_side(b); s != LinearStatus::kSolved) return s;
    scaled_b_ = row_scale_.cwiseProduct(b);
    x.resize(b.size());
    const int status = umfpack_di_wsolve(
        UMFPACK_At, rows_.starts(), rows_.indices(), rows_.values(), x.data(), scaled_b_.data(),
        numeric_, control_.data(), info_.data(), int_workspace_.data(), workspace_.data());
    if (status < 0) return umfpack_failure("umfpack_di_wsolve", status);
    if (!x.allFinite()) {
      return fail(LinearStatus::kSingular, "the solution is not finite (J numerically singular)");
    }
    return succeed();
  }

 private:
  LinearStatus umfpack_failure(const char* call, int status) {
    std::ostringstream os;
    os << call << " failed with UMFPACK status " << status
       << (status == UMFPACK_ERROR_out_of_memory ? " (out of memory)" : "");
    size_ = -1;
    return fail(LinearStatus::kPackageFailure, os.str());
  }
  void release() {
    if (numeric_ != nullptr) umfpack_di_free_numeric(&numeric_);
    if (symbolic_ != nullptr) umfpack_di_free_symbolic(&symbolic_);
  }

  std::array<double, UMFPACK_CONTROL> control_{};
  std::array<double, UMFPACK_INFO> info_{};
  void* symbolic_ = nullptr;
  void* numeric_ = nullptr;
  int symbolic_analyses_ = 0;
  std::vector<int> int_workspace_;
  std::vector<double> workspace_;
  detail::EquilibratedRows rows_;  // J's pattern and values (the solve's refinement reads them)
  Vector<Dynamic> scaled_b_;
};

}  // namespace nlobs
