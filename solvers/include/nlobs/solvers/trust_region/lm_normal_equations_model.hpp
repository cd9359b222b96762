#pragma once
// The linear algebra of a Levenberg–Marquardt step on a sparse J (run-time size): the damped
// normal equations (JᵀJ + λD²) p = −Jᵀ F factored by CHOLMOD (NormalEquationsCholesky), Moré's λ
// found as on the dense path (lmpar's safeguarded Newton iteration on ‖D p(λ)‖ = Δ, its
// derivative from the Cholesky factor L: φ'(λ) = −‖L⁻¹ P D p‖² / ‖D p‖ in the scaled variables
// q = D p, [Mor78] §5), one factorisation per λ tried on one symbolic analysis per pattern.
// Where LmQrModel solves a rank-deficient J with the basic Gauss–Newton step, this model cannot
// (JᵀJ is not positive definite): the step at the smallest λ > 0 that factors stands in for it. The
// normal equations square κ(J) (normal_equations_cholesky.hpp). LevenbergMarquardtEngine's sparse
// step model.
#include <string>
#include <vector>

#include "nlobs/solvers/linear/normal_equations_cholesky.hpp"
#include "nlobs/solvers/sparse/sparse_jacobian.hpp"
#include "nlobs/solvers/summary.hpp"
#include "nlobs/solvers/types.hpp"

namespace nlobs::detail {

class LmNormalEquationsModel {
 public:
  using JacobianMatrix = SparseJacobian;

  void resize(Index n, Index m);
  SparseJacobian& jacobian() { return jac_; }
  bool finite() const;
  void gradient(const Vector<Dynamic>& f, Vector<Dynamic>& g) const;
  void freeze(const Eigen::Array<bool, Dynamic, 1>& frozen);
  void column_norms(Vector<Dynamic>& norms) const;
  double factor(const Vector<Dynamic>& f, double fnorm, const Vector<Dynamic>& d,
                const Vector<Dynamic>& norms);
  // NaN when no λ gives a positive definite JᵀJ + λD² (J not finite in effect).
  double find_lambda(double delta, double lambda, Vector<Dynamic>& v);
  void multiply(const Vector<Dynamic>& p, Vector<Dynamic>& out) const;
  void damped_solve(double lambda, Vector<Dynamic>& r, Vector<Dynamic>& a);
  // linear_solver "cholmod", linear_setups = the numeric factorisations.
  void report(Summary& summary) const;

 private:
  // q = −(J̃ᵀJ̃ + E + λI)⁻¹ g̃ from the current factor into q_, ‖q‖ returned (inf if not finite).
  double scaled_step();
  // The step at the smallest λ that factors (0 when J̃ᵀJ̃ + E is positive definite) into base_q_,
  // its norm and ‖L⁻¹Pq‖/‖q‖; false when none does.
  bool base_step();

  SparseJacobian jac_;
  NormalEquationsCholesky cholesky_;
  std::vector<char> frozen_;
  Vector<Dynamic> d_, scaled_gradient_, q_, w_, y_, rhs_;
  double largest_diagonal_ = 0.0;  // max_j ‖J̃ e_j‖²: the size of J̃ᵀJ̃, for a λ that regularises
  bool valid_ = false;             // d, g̃ and J̃ᵀJ̃'s size finite at this Jacobian
  // The base step of this Jacobian (base_step()), kept across its rejected steps.
  bool base_ready_ = false;
  double base_lambda_ = 0.0, base_norm_ = 0.0, base_curvature_ = 1.0;
  double floor_ = -1.0;  // the largest λ that failed to factor at this Jacobian (−1: none)
  Vector<Dynamic> base_q_;
};

}  // namespace nlobs::detail
