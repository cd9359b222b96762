#pragma once
// The linear-algebra layer of the Newton-type engines, shaped as KINSOL's SUNLinearSolver and
// PETSc's KSP/PC: a LinearSolver is set up once per Jacobian (KINSOL's lsetup: factor J, or
// build a preconditioner from it) and then solves J x = b for one or more right-hand sides
// (lsolve). A LinearPreconditioner is a separate, swappable object that the Krylov solvers apply.
// Direct solvers (dense LU, band LU, sparse LU, KLU) solve to rounding; Krylov solvers (GMRES,
// BiCGSTAB) stop at ‖b − J x‖₂ ≤ tolerance · ‖b‖₂, the inexact-Newton test of [DES82].
//
// Every failure is a status with a message naming it (a singular factor and where, a Krylov
// breakdown, the iteration budget spent, a non-finite value from the matrix or the
// preconditioner); nothing throws for a numerical failure. Options that are invalid throw
// InvalidInput at construction.
//
// Dynamic sizes only: the fixed-size dense paths of the engines keep their own Eigen
// factorisations and their zero-allocation guarantee.
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <string>
#include <string_view>

#include "nlobs/solvers/sparse/sparse_jacobian.hpp"
#include "nlobs/solvers/types.hpp"

namespace nlobs {

enum class LinearStatus {
  kSolved,     // direct: factored / solved; Krylov: ‖b − J x‖₂ ≤ tolerance · ‖b‖₂
  kSingular,   // a zero (or negligible) pivot: J, or the preconditioner, is singular
  kBreakdown,  // a Krylov recurrence divided by zero before reaching the tolerance
  kNotConverged,    // the Krylov iteration budget was spent above the tolerance
  kNonFinite,       // J, b, or the preconditioner's output holds a NaN or an infinity
  kInvalidInput,    // sizes that do not match, or solve() before a successful setup()
  kPackageFailure,  // the library underneath failed (KLU out of memory); the message says how
};

inline std::string_view to_string(LinearStatus status) {
  switch (status) {
    case LinearStatus::kSolved:
      return "solved";
    case LinearStatus::kSingular:
      return "singular";
    case LinearStatus::kBreakdown:
      return "breakdown";
    case LinearStatus::kNotConverged:
      return "not_converged";
    case LinearStatus::kNonFinite:
      return "non_finite";
    case LinearStatus::kInvalidInput:
      return "invalid_input";
    case LinearStatus::kPackageFailure:
      return "package_failure";
  }
  return "unknown";
}

// What a linear solver has done since construction; an engine copies it into its Summary.
struct LinearStats {
  int setups = 0;              // setup() calls: factorisations, or preconditioner builds
  int solves = 0;              // solve() calls
  int iterations = 0;          // Krylov iterations over all solves (0 for direct solvers)
  int failures = 0;            // setup() or solve() calls that did not return kSolved
  double last_residual = 0.0;  // ‖b − J x‖₂ / ‖b‖₂ of the last Krylov solve (0 for direct)
};

class LinearSolver {
 public:
  // Direct solvers: J is singular when, with each row scaled to max_j |J_ij| = 1, a pivot
  // |U_kk| is at or below this (KLU: its pivot ratio min|U_kk| / max|U_kk| after its own row
  // scaling). Scaling first keeps a badly scaled but regular J, diag(1e20, 1), regular.
  static constexpr double kSingularPivot = 1e-13;

  virtual ~LinearSolver() = default;
  virtual std::string_view name() const = 0;
  // Direct solvers solve to rounding and ignore solve()'s tolerance.
  virtual bool iterative() const = 0;
  // Factor J (direct) or take J as the operator and build the preconditioner from it (Krylov).
  // The solver keeps what it needs; J may change afterwards.
  virtual LinearStatus setup(const SparseJacobian& jac) = 0;
  // x with J x = b (direct) or ‖b − J x‖₂ ≤ tolerance · ‖b‖₂ (Krylov, from x = 0). x is resized.
  virtual LinearStatus solve(const Vector<Dynamic>& b, Vector<Dynamic>& x, double tolerance) = 0;

  const LinearStats& stats() const { return stats_; }
  // Why the last call did not return kSolved (empty after a success).
  const std::string& message() const { return message_; }

 protected:
  LinearStatus succeed() {
    message_.clear();
    return LinearStatus::kSolved;
  }
  LinearStatus fail(LinearStatus status, std::string message) {
    ++stats_.failures;
    message_ = std::string(name()) + ": " + std::move(message);
    return status;
  }
  // kSolved when J is square, of size n when n ≥ 0, and finite; otherwise the failure, named.
  LinearStatus check_matrix(const SparseJacobian& jac, Index n = -1);
  // kSolved when b has the size of the last successful setup() and is finite.
  LinearStatus check_right_hand_side(const Vector<Dynamic>& b);
  // row_scale_ = 1 / max_j |J_ij| per row; kSingular naming the first zero row.
  LinearStatus equilibrate_rows(const SparseJacobian& jac);
  Vector<Dynamic> row_scale_;
  Index size_ = -1;  // n of the last successful setup(); −1 before one
  LinearStats stats_;
  std::string message_;
};

// z = M⁻¹ r with M ≈ J: applied by the Krylov solvers on the right, J M⁻¹ u = b, x = M⁻¹ u, so
// that the residual they measure is the true one.
class LinearPreconditioner {
 public:
  virtual ~LinearPreconditioner() = default;
  virtual std::string_view name() const = 0;
  // Build M from J (a square matrix); kSingular or kNonFinite with message() when it cannot.
  virtual LinearStatus setup(const SparseJacobian& jac) = 0;
  // z = M⁻¹ r, r of the size of the last setup(); z is resized. Jacobi and ILU(0) allocate
  // nothing once sized; ILUT does (Eigen's IncompleteLUT permutes through temporaries).
  virtual void apply(const Vector<Dynamic>& r, Vector<Dynamic>& z) = 0;
  const std::string& message() const { return message_; }

 protected:
  std::string message_;
};

namespace detail {
// The first row (or column) of a square J that is not finite, or −1.
inline Index first_non_finite_row(const SparseJacobian& jac) {
  for (Index i = 0; i < jac.outerSize(); ++i) {
    for (SparseJacobian::InnerIterator it(jac, i); it; ++it) {
      if (!std::isfinite(it.value())) return i;
    }
  }
  return -1;
}
}  // namespace detail

inline LinearStatus LinearSolver::equilibrate_rows(const SparseJacobian& jac) {
  row_scale_.resize(jac.rows());
  for (Index i = 0; i < jac.outerSize(); ++i) {
    double largest = 0.0;
    for (SparseJacobian::InnerIterator it(jac, i); it; ++it) {
      largest = std::max(largest, std::abs(it.value()));
    }
    if (largest == 0.0) {
      return fail(LinearStatus::kSingular, "J is singular: row " + std::to_string(i) + " is zero");
    }
    row_scale_[i] = 1.0 / largest;
  }
  return LinearStatus::kSolved;
}

inline LinearStatus LinearSolver::check_matrix(const SparseJacobian& jac, Index n) {
  size_ = -1;  // until this setup succeeds, solve() refuses
  if (jac.rows() != jac.cols() || jac.rows() < 1 || (n >= 0 && jac.rows() != n)) {
    return fail(LinearStatus::kInvalidInput,
                "J is " + std::to_string(jac.rows()) + "x" + std::to_string(jac.cols()) +
                    (n >= 0 ? ", expected " + std::to_string(n) + "x" + std::to_string(n)
                            : std::string(", not square")));
  }
  if (const Index row = detail::first_non_finite_row(jac); row >= 0) {
    return fail(LinearStatus::kNonFinite, "J has a non-finite entry in row " + std::to_string(row));
  }
  return LinearStatus::kSolved;
}

inline LinearStatus LinearSolver::check_right_hand_side(const Vector<Dynamic>& b) {
  if (size_ < 0) return fail(LinearStatus::kInvalidInput, "solve() before a successful setup()");
  if (b.size() != size_) {
    return fail(LinearStatus::kInvalidInput, "b has " + std::to_string(b.size()) +
                                                 " components, J is " + std::to_string(size_) +
                                                 "x" + std::to_string(size_));
  }
  if (!b.allFinite()) return fail(LinearStatus::kNonFinite, "b is not finite");
  return LinearStatus::kSolved;
}

}  // namespace nlobs
