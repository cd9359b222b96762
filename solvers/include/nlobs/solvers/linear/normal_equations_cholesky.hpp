#pragma once
// The damped normal equations of a sparse least-squares step, factored by SuiteSparse's CHOLMOD
// [CDHR08] (supernodal or simplicial LLᵀ, fill-reducing ordering by AMD or METIS):
//   (J̃ᵀ J̃ + E + λ I) q = b,   J̃ = J D⁻¹,
// J m×n sparse (m ≥ n, or square), D = diag(d) > 0 a column scaling, E = diag(e), e_j = 1 for a
// frozen column (a variable an active bound holds: its column of J̃ is zero, and E keeps the
// matrix regular there) and 0 otherwise. The symbolic analysis is done once per pattern of J; a
// factorisation per λ reuses it (what a Levenberg–Marquardt step's λ search needs).
//
// The normal equations square J's condition number (κ(JᵀJ) = κ(J)²): a Jacobian with κ above
// 1e8 loses every digit of a Gauss–Newton step (λ = 0) that QR would keep. That is the price of a
// sparse Cholesky factor; the dense path (QR with column pivoting) has not got it.
//
// CHOLMOD stays behind this header (pimpl): cholmod.h is not included by users of the engines.
#include <memory>
#include <string>
#include <vector>

#include "nlobs/solvers/sparse/sparse_jacobian.hpp"
#include "nlobs/solvers/types.hpp"

namespace nlobs {

class NormalEquationsCholesky {
 public:
  NormalEquationsCholesky();
  ~NormalEquationsCholesky();
  NormalEquationsCholesky(const NormalEquationsCholesky&) = delete;
  NormalEquationsCholesky& operator=(const NormalEquationsCholesky&) = delete;

  // J̃ = J diag(1/d) and E from `frozen` (one flag per column, empty for none); analyses the
  // pattern when it differs from the last one's. jac compressed, m×n with n = d.size(); d finite
  // and > 0 (InvalidInput otherwise, and for non-finite entries of J).
  void load(const SparseJacobian& jac, const Vector<Dynamic>& d, const std::vector<char>& frozen);
  // L Lᵀ = P (J̃ᵀ J̃ + E + λ I) Pᵀ, λ ≥ 0. false when the matrix is not numerically positive
  // definite (J̃ rank-deficient at λ = 0, or λ below rounding of a singular J̃ᵀJ̃), message() says
  // at which column; the last successful factor is then gone.
  bool factor(double lambda);
  // q = (J̃ᵀ J̃ + E + λ I)⁻¹ b with the last factor (factor() returned true).
  void solve(const Vector<Dynamic>& b, Vector<Dynamic>& q);
  // y = L⁻¹ P b: ‖y‖² = bᵀ (J̃ᵀ J̃ + E + λ I)⁻¹ b, the derivative Moré's λ iteration needs.
  void solve_lower(const Vector<Dynamic>& b, Vector<Dynamic>& y);

  Index size() const;
  double lambda() const { return lambda_; }  // of the last factor
  bool factored() const { return factored_; }
  int analyses() const { return analyses_; }
  int factorisations() const { return factorisations_; }
  const std::string& message() const { return message_; }

 private:
  struct Cholmod;  // CHOLMOD's common block, factor, workspaces and the matrix J̃ᵀ with E
  std::unique_ptr<Cholmod> cholmod_;
  double lambda_ = 0.0;
  bool factored_ = false;
  int analyses_ = 0, factorisations_ = 0;
  std::string message_;
};

}  // namespace nlobs
