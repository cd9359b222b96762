#pragma once
// What the Krylov solvers share: the operator v ↦ J v — the assembled J (setup(J)) or a
// Jacobian-free product such as one forward-mode AD direction or a difference quotient
// (setup(Operator, n)) — and a right preconditioner M ≈ J (none, or one of preconditioners.hpp
// built from the assembled J or from an approximation of it).
#include <functional>
#include <memory>
#include <string>
#include <utility>

#include "nlobs/common/invalid_input.hpp"
#include "nlobs/solvers/linear/linear_solver.hpp"

namespace nlobs {

class KrylovSolver : public LinearSolver {
 public:
  using Operator = std::function<void(const Vector<Dynamic>& v, Vector<Dynamic>& jv)>;

  bool iterative() const override { return true; }
  // The preconditioner, or nullptr (none: M = I).
  LinearPreconditioner* preconditioner() const { return preconditioner_.get(); }

  // The operator is J itself; the preconditioner is built from it.
  LinearStatus setup(const SparseJacobian& jac) override {
    ++stats_.setups;
    if (const LinearStatus s = check_matrix(jac); s != LinearStatus::kSolved) return s;
    matrix_ = jac;
    assembled_ = true;
    jacobian_free_ = {};
    return setup_preconditioner(&jac, jac.rows());
  }
  // Jacobian-free: J v by `jv` (n×n); the preconditioner, if there is one, is built from
  // `approximation` (required then: a preconditioner needs a matrix). The solver keeps `jv`;
  // `approximation` may change afterwards.
  LinearStatus setup(Operator jv, Index n, const SparseJacobian* approximation = nullptr) {
    ++stats_.setups;
    size_ = -1;
    if (!jv || n < 1) {
      return fail(LinearStatus::kInvalidInput, "the operator is empty or n = " + std::to_string(n));
    }
    assembled_ = false;
    jacobian_free_ = std::move(jv);
    if (preconditioner_ && approximation == nullptr) {
      return fail(LinearStatus::kInvalidInput, "a Jacobian-free setup with preconditioner " +
                                                   std::string(preconditioner_->name()) +
                                                   " needs an approximation of J");
    }
    if (approximation != nullptr) {
      if (const LinearStatus s = check_matrix(*approximation, n); s != LinearStatus::kSolved) {
        return s;
      }
    }
    return setup_preconditioner(approximation, n);
  }

 protected:
  explicit KrylovSolver(std::unique_ptr<LinearPreconditioner> preconditioner)
      : preconditioner_(std::move(preconditioner)) {}

  // jv = J v; false (with the failure recorded) when it is not finite.
  bool multiply(const Vector<Dynamic>& v, Vector<Dynamic>& jv) {
    if (assembled_) {
      jv.noalias() = matrix_ * v;
    } else {
      jacobian_free_(v, jv);
    }
    if (jv.size() == size_ && jv.allFinite()) return true;
    fail(LinearStatus::kNonFinite, jv.size() != size_ ? "J v has size " + std::to_string(jv.size())
                                                      : std::string("J v is not finite"));
    return false;
  }
  // z = M⁻¹ r; false (recorded) when the preconditioner returns a non-finite or missized z.
  bool precondition(const Vector<Dynamic>& r, Vector<Dynamic>& z) {
    if (!preconditioner_) {
      z = r;
      return true;
    }
    preconditioner_->apply(r, z);
    if (z.size() == size_ && z.allFinite()) return true;
    fail(LinearStatus::kNonFinite,
         "preconditioner " + std::string(preconditioner_->name()) +
             (z.size() != size_ ? " returned a vector of size " + std::to_string(z.size())
                                : std::string(" returned a non-finite value")));
    return false;
  }
  // kSolved, or kInvalidInput for a tolerance outside (0, 1).
  LinearStatus check_tolerance(double tolerance) {
    if (tolerance > 0.0 && tolerance < 1.0) return LinearStatus::kSolved;
    return fail(LinearStatus::kInvalidInput,
                "tolerance " + std::to_string(tolerance) + " must lie in (0, 1)");
  }

 private:
  // jac is null only without a preconditioner.
  LinearStatus setup_preconditioner(const SparseJacobian* jac, Index n) {
    if (preconditioner_) {
      const LinearStatus s = preconditioner_->setup(*jac);
      if (s != LinearStatus::kSolved) {
        return fail(s, preconditioner_->message().empty()
                           ? "preconditioner " + std::string(preconditioner_->name()) + ": " +
                                 std::string(to_string(s))
                           : preconditioner_->message());
      }
    }
    size_ = n;
    return succeed();
  }

  std::unique_ptr<LinearPreconditioner> preconditioner_;
  SparseJacobian matrix_;  // a copy: J may change between setup() and solve()
  bool assembled_ = false;
  Operator jacobian_free_;
};

}  // namespace nlobs
