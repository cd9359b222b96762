#pragma once
// Preconditioners for the Krylov solvers, built from the assembled (coloured) Jacobian:
//   jacobi     M = diag(J)                                    O(n) to build and apply
//   ilu0       M = L U with L, U on J's own pattern, ILU(0)   O(nnz) memory, [Saa03, §10.3]
//   ilut       M = L U keeping entries above a drop tolerance, at most fill_factor × the
//              entries of J per row, ILUT [Saa03, §10.4] (Eigen's IncompleteLUT)
//   callable   the user's: a setup(J) and an apply(r, z)
// A preconditioner that cannot be built says why (Jacobi and ILU(0): which row has a zero
// diagonal entry or pivot; ILUT: Eigen reports no row).
#include <Eigen/IterativeLinearSolvers>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <sstream>
#include <utility>
#include <vector>

#include "nlobs/common/invalid_input.hpp"
#include "nlobs/solvers/linear/linear_solver.hpp"

namespace nlobs {

class JacobiPreconditioner final : public LinearPreconditioner {
 public:
  std::string_view name() const override { return "jacobi"; }
  LinearStatus setup(const SparseJacobian& jac) override {
    inverse_diagonal_.resize(jac.rows());
    for (Index i = 0; i < jac.rows(); ++i) {
      const double d = jac.coeff(i, i);
      if (!(std::abs(d) > 0.0) || !std::isfinite(d)) {
        std::ostringstream os;
        os << "jacobi: diagonal entry J(" << i << ", " << i << ") = " << d << " cannot be inverted";
        message_ = os.str();
        return std::isfinite(d) ? LinearStatus::kSingular : LinearStatus::kNonFinite;
      }
      inverse_diagonal_[i] = 1.0 / d;
    }
    message_.clear();
    return LinearStatus::kSolved;
  }
  void apply(const Vector<Dynamic>& r, Vector<Dynamic>& z) override {
    z = inverse_diagonal_.cwiseProduct(r);
  }

 private:
  Vector<Dynamic> inverse_diagonal_;
};

// ILU(0), the IKJ variant of [Saa03, Algorithm 10.4] on J's compressed rows: the factors share
// J's pattern, so J must hold its whole diagonal.
class Ilu0Preconditioner final : public LinearPreconditioner {
 public:
  std::string_view name() const override { return "ilu0"; }
  LinearStatus setup(const SparseJacobian& jac) override {
    lu_ = jac;
    lu_.makeCompressed();
    const Index n = lu_.rows();
    const int* start = lu_.outerIndexPtr();
    const int* column = lu_.innerIndexPtr();
    double* value = lu_.valuePtr();
    diagonal_.assign(static_cast<std::size_t>(n), -1);
    position_.assign(static_cast<std::size_t>(n), -1);
    for (Index i = 0; i < n; ++i) {
      for (int k = start[i]; k < start[i + 1]; ++k) {
        if (column[k] == i) diagonal_[static_cast<std::size_t>(i)] = k;
      }
      if (diagonal_[static_cast<std::size_t>(i)] < 0) {
        return refuse(LinearStatus::kSingular, i, "J(i, i) is not in J's pattern");
      }
    }
    for (Index i = 0; i < n; ++i) {
      for (int k = start[i]; k < start[i + 1]; ++k)
        position_[static_cast<std::size_t>(column[k])] = k;
      for (int k = start[i]; k < start[i + 1] && column[k] < i; ++k) {
        const int row = column[k];  // eliminate U's row `row` from row i
        const double pivot = value[diagonal_[static_cast<std::size_t>(row)]];
        value[k] /= pivot;
        for (int e = diagonal_[static_cast<std::size_t>(row)] + 1; e < start[row + 1]; ++e) {
          const int target = position_[static_cast<std::size_t>(column[e])];
          if (target >= 0) value[target] -= value[k] * value[e];
        }
      }
      for (int k = start[i]; k < start[i + 1]; ++k)
        position_[static_cast<std::size_t>(column[k])] = -1;
      const double pivot = value[diagonal_[static_cast<std::size_t>(i)]];
      if (!std::isfinite(pivot)) return refuse(LinearStatus::kNonFinite, i, "pivot not finite");
      double row_size = 0.0;  // of J's row i: a pivot at rounding level beside it is zero
      for (SparseJacobian::InnerIterator it(jac, i); it; ++it) {
        row_size = std::max(row_size, std::abs(it.value()));
      }
      if (!(std::abs(pivot) > std::numeric_limits<double>::epsilon() * row_size)) {
        return refuse(LinearStatus::kSingular, i, "zero pivot");
      }
    }
    message_.clear();
    return LinearStatus::kSolved;
  }
  void apply(const Vector<Dynamic>& r, Vector<Dynamic>& z) override {
    const Index n = lu_.rows();
    const int* start = lu_.outerIndexPtr();
    const int* column = lu_.innerIndexPtr();
    const double* value = lu_.valuePtr();
    z = r;
    for (Index i = 0; i < n; ++i) {  // L y = r, L unit lower
      double sum = z[i];
      for (int k = start[i]; k < diagonal_[static_cast<std::size_t>(i)]; ++k)
        sum -= value[k] * z[column[k]];
      z[i] = sum;
    }
    for (Index i = n - 1; i >= 0; --i) {  // U z = y
      double sum = z[i];
      const int d = diagonal_[static_cast<std::size_t>(i)];
      for (int k = d + 1; k < start[i + 1]; ++k) sum -= value[k] * z[column[k]];
      z[i] = sum / value[d];
    }
  }

 private:
  LinearStatus refuse(LinearStatus status, Index row, const char* why) {
    std::ostringstream os;
    os << "ilu0: row " << row << ": " << why;
    message_ = os.str();
    return status;
  }
  SparseJacobian lu_;
  std::vector<int> diagonal_, position_;
};

struct IlutOptions {
  double drop_tolerance = 1e-4;  // entries below this × the row's norm are dropped, > 0
  int fill_factor = 10;          // at most fill_factor × J's entries per row, ≥ 1
};

class IlutPreconditioner final : public LinearPreconditioner {
 public:
  explicit IlutPreconditioner(IlutOptions options = {}) : options_(options) {
    if (!(options_.drop_tolerance > 0.0 && options_.drop_tolerance < 1.0)) {
      std::ostringstream os;
      os << "IlutOptions::drop_tolerance = " << options_.drop_tolerance << " must lie in (0, 1)";
      throw InvalidInput(os.str());
    }
    if (options_.fill_factor < 1) {
      throw InvalidInput("IlutOptions::fill_factor = " + std::to_string(options_.fill_factor) +
                         " must be >= 1");
    }
    ilut_.setDroptol(options_.drop_tolerance);
    ilut_.setFillfactor(options_.fill_factor);
  }
  std::string_view name() const override { return "ilut"; }
  LinearStatus setup(const SparseJacobian& jac) override {
    if (const Index row = detail::first_non_finite_row(jac); row >= 0) {
      message_ = "ilut: J has a non-finite entry in row " + std::to_string(row);
      return LinearStatus::kNonFinite;
    }
    ilut_.compute(jac);
    if (ilut_.info() != Eigen::Success) {
      message_ = "ilut: the incomplete factorisation failed (Eigen IncompleteLUT)";
      return LinearStatus::kSingular;
    }
    message_.clear();
    return LinearStatus::kSolved;
  }
  void apply(const Vector<Dynamic>& r, Vector<Dynamic>& z) override { z = ilut_.solve(r); }

 private:
  IlutOptions options_;
  Eigen::IncompleteLUT<double, int> ilut_;
};

// A user's preconditioner: setup(J) → LinearStatus (may be empty: nothing to build) and
// apply(r, z) with z = M⁻¹ r. The Krylov solvers check apply's output for NaN.
class CallablePreconditioner final : public LinearPreconditioner {
 public:
  using Setup = std::function<LinearStatus(const SparseJacobian&)>;
  using Apply = std::function<void(const Vector<Dynamic>&, Vector<Dynamic>&)>;
  CallablePreconditioner(Apply apply, Setup setup = {})
      : apply_(std::move(apply)), setup_(std::move(setup)) {
    if (!apply_) throw InvalidInput("CallablePreconditioner: apply is empty");
  }
  std::string_view name() const override { return "user"; }
  LinearStatus setup(const SparseJacobian& jac) override {
    const LinearStatus status = setup_ ? setup_(jac) : LinearStatus::kSolved;
    message_ = status == LinearStatus::kSolved
                   ? std::string()
                   : "user preconditioner: setup returned " + std::string(to_string(status));
    return status;
  }
  void apply(const Vector<Dynamic>& r, Vector<Dynamic>& z) override { apply_(r, z); }

 private:
  Apply apply_;
  Setup setup_;
};

}  // namespace nlobs
