#pragma once
// The linear algebra of a Levenberg–Marquardt step on a dense J, as MINPACK's lmder does it
// ([Mor78], [MINPACK80]): J P = Q R (QR with column pivoting), Moré's λ by a safeguarded Newton
// iteration on ‖D p(λ)‖ = Δ (lmpar), each p(λ) from R and √λ D eliminated by Givens rotations
// (qrsolv) — the normal equations are never formed. LevenbergMarquardtEngine's step model for
// every fixed size and for a run-time size without a sparse Jacobian (the interface is described
// there; LmNormalEquationsModel is the sparse one).
#include <Eigen/Householder>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>

#include "nlobs/solvers/summary.hpp"
#include "nlobs/solvers/types.hpp"

namespace nlobs::detail {

template <int N>
class LmQrModel {
 public:
  using JacobianMatrix = Matrix<Dynamic, N>;

  void resize(Index n, Index m) {
    if constexpr (N == Dynamic) {
      for (Vector<N>* v : {&diag_p_, &qtf_, &z_, &w_, &sdiag_, &b_, &qtr_}) v->resize(n);
      perm_.resize(n), r_.resize(n, n), s_.resize(n, n);
    }
    if (work_m_.size() != m) work_m_.resize(m);
    if (jac_.rows() != m || jac_.cols() != n) jac_.resize(m, n);
    // qr_ sizes itself in compute(): allocates when m changes, never after.
  }
  JacobianMatrix& jacobian() { return jac_; }
  bool finite() const { return jac_.allFinite(); }
  // g = −Jᵀ f.
  void gradient(const Vector<Dynamic>& f, Vector<N>& g) const {
    g.noalias() = -(jac_.transpose() * f);
  }
  // The columns of the variables a bound holds zeroed.
  void freeze(const Eigen::Array<bool, N, 1>& frozen) {
    for (Index k = 0; k < frozen.size(); ++k) {
      if (frozen[k]) jac_.col(k).setZero();
    }
  }
  void column_norms(Vector<N>& norms) const { norms = jac_.colwise().norm().transpose(); }
  // Factors J for the steps at this Jacobian under D = diag(d); returns MINPACK's gtol measure,
  // max_j |cos(f, J e_j)| over the columns of non-zero norm.
  double factor(const Vector<Dynamic>& f, double fnorm, const Vector<N>& d,
                const Vector<N>& norms) {
    const Index n = jac_.cols();
    qr_.compute(jac_);
    r_ = qr_.matrixR().topRows(n).template triangularView<Eigen::Upper>();
    for (Index j = 0; j < n; ++j) {
      perm_[j] = qr_.colsPermutation().indices()[j];
      diag_p_[j] = d[perm_[j]];
    }
    work_m_ = f;
    work_m_.applyOnTheLeft(qr_.householderQ().adjoint());
    qtf_ = work_m_.head(n);
    double cosine = 0.0;
    if (fnorm > 0.0) {
      for (Index j = 0; j < n; ++j) {
        const double norm = norms[perm_[j]];
        if (norm == 0.0) continue;
        cosine =
            std::max(cosine, std::abs(r_.col(j).head(j + 1).dot(qtf_.head(j + 1)) / fnorm) / norm);
      }
    }
    return cosine;
  }
  // Moré's λ for radius Δ from the guess λ (lmpar); the step p(λ) in x's order into v.
  double find_lambda(double delta, double lambda, Vector<N>& v);
  // out = J p.
  void multiply(const Vector<N>& p, Vector<Dynamic>& out) const { out.noalias() = jac_ * p; }
  // a = −(JᵀJ + λD²)⁻¹ Jᵀ r (r is overwritten).
  void damped_solve(double lambda, Vector<Dynamic>& r, Vector<N>& a) {
    const Index n = jac_.cols();
    r.applyOnTheLeft(qr_.householderQ().adjoint());
    qtr_ = r.head(n);
    solve_damped(lambda, qtr_, z_);
    for (Index j = 0; j < n; ++j) a[perm_[j]] = -z_[j];
  }
  void report(Summary&) const {}

 private:
  // min ‖[R; √λ D_P] z − [b; 0]‖ (MINPACK's qrsolv) into z; leaves S (the triangular factor of
  // the augmented matrix) in s_ and its diagonal in sdiag_.
  void solve_damped(double lambda, const Vector<N>& b, Vector<N>& z);

  JacobianMatrix jac_;
  Eigen::ColPivHouseholderQR<JacobianMatrix> qr_;
  Matrix<N, N> r_, s_;
  Eigen::Matrix<Index, N, 1> perm_;
  Vector<N> diag_p_ = zero_vector<N>(), qtf_ = zero_vector<N>(), z_ = zero_vector<N>(),
            w_ = zero_vector<N>(), sdiag_ = zero_vector<N>(), b_ = zero_vector<N>(),
            qtr_ = zero_vector<N>();
  Vector<Dynamic> work_m_;
};

template <int N>
void LmQrModel<N>::solve_damped(double lambda, const Vector<N>& b, Vector<N>& z) {
  const Index n = r_.rows();
  s_ = r_.template triangularView<Eigen::Upper>();
  b_ = b;
  const double root = std::sqrt(lambda);
  for (Index j = 0; j < n; ++j) {
    const double dj = root * diag_p_[j];
    if (dj == 0.0) continue;
    // The row [0 … √λ D_j … 0 | 0] of the augmented system, eliminated against S by rotations.
    w_.setZero();
    w_[j] = dj;
    double extra = 0.0;  // its right-hand side
    for (Index k = j; k < n; ++k) {
      if (w_[k] == 0.0) continue;
      const double radius = std::hypot(s_(k, k), w_[k]);
      const double c = s_(k, k) / radius, s = w_[k] / radius;  // [c s; −s c] zeroes w_k
      for (Index i = k; i < n; ++i) {
        const double top = s_(k, i), bottom = w_[i];
        s_(k, i) = c * top + s * bottom;
        w_[i] = -s * top + c * bottom;
      }
      const double top = b_[k];
      b_[k] = c * top + s * extra;
      extra = -s * top + c * extra;
    }
  }
  sdiag_ = s_.diagonal();
  // Back substitution; a zero diagonal ends the non-singular part (the rest of z is 0).
  Index rank = n;
  for (Index j = 0; j < n; ++j) {
    if (s_(j, j) == 0.0) {
      rank = j;
      break;
    }
  }
  z.setZero();
  for (Index j = rank - 1; j >= 0; --j) {
    double sum = b_[j];
    for (Index i = j + 1; i < rank; ++i) sum -= s_(j, i) * z[i];
    z[j] = sum / s_(j, j);
  }
}

template <int N>
double LmQrModel<N>::find_lambda(double delta, double lambda, Vector<N>& v) {
  const Index n = r_.rows();
  const double dwarf = std::numeric_limits<double>::min();
  // Gauss–Newton direction R z = Qᵀ F; rank-deficient R: components past the first zero
  // diagonal are 0.
  Index rank = n;
  for (Index j = 0; j < n; ++j) {
    if (r_(j, j) == 0.0) {
      rank = j;
      break;
    }
  }
  z_.setZero();
  for (Index j = rank - 1; j >= 0; --j) {
    double sum = qtf_[j];
    for (Index i = j + 1; i < rank; ++i) sum -= r_(j, i) * z_[i];
    z_[j] = sum / r_(j, j);
  }
  double dxnorm = diag_p_.cwiseProduct(z_).norm();
  double fp = dxnorm - delta;
  if (fp <= 0.1 * delta) {
    for (Index j = 0; j < n; ++j) v[perm_[j]] = -z_[j];
    return 0.0;
  }

  // Bounds on λ: parl from the Newton step of the secular equation at λ = 0 (full rank only),
  // paru = ‖D⁻¹ Jᵀ F‖ / Δ.
  double parl = 0.0;
  if (rank == n) {
    w_ = diag_p_.cwiseProduct(diag_p_.cwiseProduct(z_)) / dxnorm;
    for (Index j = 0; j < n; ++j) {
      double sum = w_[j];
      for (Index i = 0; i < j; ++i) sum -= r_(i, j) * w_[i];
      w_[j] = sum / r_(j, j);
    }
    const double t = w_.norm();
    parl = ((fp / delta) / t) / t;
  }
  for (Index j = 0; j < n; ++j) {
    w_[j] = r_.col(j).head(j + 1).dot(qtf_.head(j + 1)) / diag_p_[j];
  }
  const double gnorm = w_.norm();
  double paru = gnorm / delta;
  if (paru == 0.0) paru = dwarf / std::min(delta, 0.1);

  lambda = std::min(std::max(lambda, parl), paru);  // MINPACK's order (parl > paru by rounding)
  if (lambda == 0.0) lambda = gnorm / dxnorm;
  for (int iteration = 1;; ++iteration) {
    if (lambda == 0.0) lambda = std::max(dwarf, 0.001 * paru);
    solve_damped(lambda, qtf_, z_);
    dxnorm = diag_p_.cwiseProduct(z_).norm();
    const double previous = fp;
    fp = dxnorm - delta;
    // |‖Dp‖ − Δ| ≤ 0.1 Δ, or λ at its lower bound 0 with ‖Dp‖ < Δ still, or ten iterations.
    if (std::abs(fp) <= 0.1 * delta || (parl == 0.0 && fp <= previous && previous < 0.0) ||
        iteration == 10) {
      for (Index j = 0; j < n; ++j) v[perm_[j]] = -z_[j];
      return lambda;
    }
    // Newton correction of λ on φ(λ) = ‖D p(λ)‖ − Δ, through S from solve_damped.
    w_ = diag_p_.cwiseProduct(diag_p_.cwiseProduct(z_)) / dxnorm;
    for (Index j = 0; j < n; ++j) {
      w_[j] /= sdiag_[j];
      for (Index i = j + 1; i < n; ++i) w_[i] -= s_(j, i) * w_[j];
    }
    const double t = w_.norm();
    const double correction = ((fp / delta) / t) / t;
    if (fp > 0.0) parl = std::max(parl, lambda);
    if (fp < 0.0) paru = std::min(paru, lambda);
    lambda = std::max(parl, lambda + correction);
  }
}

}  // namespace nlobs::detail
