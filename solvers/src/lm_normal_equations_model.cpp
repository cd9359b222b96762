// LmNormalEquationsModel (nlobs/solvers/trust_region/lm_normal_equations_model.hpp): Moré's λ
// iteration as LmQrModel::find_lambda has it (MINPACK's lmpar), on the scaled variables q = D p,
// where D = I and the derivative of ‖q(λ)‖ comes from the Cholesky factor instead of qrsolv's S.
#include "nlobs/solvers/trust_region/lm_normal_equations_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace nlobs::detail {
namespace {
// ε·max(max_j ‖J̃ e_j‖², 1): the smallest λ tried where λ = 0 does not factor; A + λI is positive
// definite in floating point well before λ reaches ‖A‖ (tenfold steps from here).
double regularising_lambda(double largest_diagonal) {
  return std::numeric_limits<double>::epsilon() * std::max(largest_diagonal, 1.0);
}
}  // namespace

void LmNormalEquationsModel::resize(Index n, Index m) {
  static_cast<void>(m);  // J comes sized from the problem's sparse Jacobian
  for (Vector<Dynamic>* v : {&d_, &scaled_gradient_, &q_, &w_, &y_, &rhs_, &base_q_}) {
    v->resize(n);
  }
  frozen_.assign(static_cast<std::size_t>(n), 0);
}

bool LmNormalEquationsModel::finite() const {
  return Eigen::Map<const Vector<Dynamic>>(jac_.valuePtr(), jac_.nonZeros()).allFinite();
}

void LmNormalEquationsModel::gradient(const Vector<Dynamic>& f, Vector<Dynamic>& g) const {
  g.noalias() = jac_.transpose() * f;
  g = -g;
}

void LmNormalEquationsModel::freeze(const Eigen::Array<bool, Dynamic, 1>& frozen) {
  for (Index k = 0; k < frozen.size(); ++k) frozen_[static_cast<std::size_t>(k)] = frozen[k];
}

void LmNormalEquationsModel::column_norms(Vector<Dynamic>& norms) const {
  norms.setZero();
  const int* columns = jac_.innerIndexPtr();
  const double* values = jac_.valuePtr();
  for (Index k = 0; k < jac_.nonZeros(); ++k) norms[columns[k]] += values[k] * values[k];
  for (Index j = 0; j < norms.size(); ++j) {
    norms[j] = frozen_[static_cast<std::size_t>(j)] ? 0.0 : std::sqrt(norms[j]);
  }
}

double LmNormalEquationsModel::factor(const Vector<Dynamic>& f, double fnorm,
                                      const Vector<Dynamic>& d, const Vector<Dynamic>& norms) {
  d_ = d;
  base_ready_ = false;
  // d from column norms that overflowed (J near 1e154), or a gradient that did: no step is
  // computed (find_lambda returns NaN, the engine stops on it).
  valid_ = d_.allFinite() && (d_.array() > 0.0).all();
  if (!valid_) return std::numeric_limits<double>::quiet_NaN();
  cholesky_.load(jac_, d_, frozen_);
  // g̃ = D⁻¹ Jᵀ f, a frozen variable's 0.
  scaled_gradient_.noalias() = jac_.transpose() * f;
  double cosine = 0.0;
  largest_diagonal_ = 0.0;
  for (Index j = 0; j < d_.size(); ++j) {
    if (frozen_[static_cast<std::size_t>(j)]) {
      scaled_gradient_[j] = 0.0;
      continue;
    }
    if (norms[j] != 0.0 && fnorm > 0.0) {
      cosine = std::max(cosine, std::abs(scaled_gradient_[j] / fnorm) / norms[j]);
    }
    scaled_gradient_[j] /= d_[j];
    largest_diagonal_ = std::max(largest_diagonal_, std::pow(norms[j] / d_[j], 2));
  }
  valid_ = scaled_gradient_.allFinite() && std::isfinite(largest_diagonal_);
  return cosine;
}

double LmNormalEquationsModel::scaled_step() {
  cholesky_.solve(scaled_gradient_, q_);
  q_ = -q_;
  const double norm = q_.norm();
  return std::isfinite(norm) ? norm : std::numeric_limits<double>::infinity();
}

bool LmNormalEquationsModel::base_step() {
  // λ = 0 when J̃ᵀJ̃ + E is positive definite; else the smallest of ε·max(max_j ‖J̃ e_j‖², 1)·10^k
  // that factors, whose step stands in for the Gauss–Newton step QR would take (the largest λ
  // that failed is the floor below which no λ is tried again).
  floor_ = -1.0;  // none failed yet
  base_lambda_ = 0.0;
  for (int tries = 0; tries <= 40; ++tries) {
    if (cholesky_.factor(base_lambda_)) {
      base_norm_ = scaled_step();
      if (base_norm_ < std::numeric_limits<double>::infinity()) {
        base_q_ = q_;
        if (base_norm_ > 0.0) {
          w_ = q_ / base_norm_;
          cholesky_.solve_lower(w_, y_);
          base_curvature_ = y_.norm();
        }
        return true;
      }
    }
    floor_ = base_lambda_;
    base_lambda_ =
        base_lambda_ == 0.0 ? regularising_lambda(largest_diagonal_) : 10.0 * base_lambda_;
    if (!std::isfinite(base_lambda_)) break;
  }
  return false;
}

double LmNormalEquationsModel::find_lambda(double delta, double lambda, Vector<Dynamic>& v) {
  const double dwarf = std::numeric_limits<double>::min();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  auto step_in_x = [&] { v = q_.cwiseQuotient(d_); };
  if (!valid_) return nan;
  // The base step, once per Jacobian (a rejected step's next λ search reuses it).
  if (!base_ready_) {
    if (!base_step()) return nan;
    base_ready_ = true;
  }
  double dxnorm = base_norm_, fp = dxnorm - delta, parl = 0.0;
  if (fp <= 0.1 * delta) {
    q_ = base_q_;
    step_in_x();
    return base_lambda_;
  }
  // Moré's lower bound: the Newton step on φ(λ) = ‖q(λ)‖ − Δ from the base λ, where φ > 0 (φ is
  // convex and decreasing, so the step stays below the root).
  parl = base_lambda_ + ((fp / delta) / base_curvature_) / base_curvature_;
  const double gnorm = scaled_gradient_.norm();
  double paru = gnorm / delta;
  if (paru == 0.0) paru = dwarf / std::min(delta, 0.1);
  if (!std::isfinite(paru) || !std::isfinite(parl)) return nan;
  lambda = std::min(std::max(lambda, parl), paru);
  if (lambda == 0.0 && dxnorm > 0.0) lambda = gnorm / dxnorm;
  int failures = 0;
  for (int iteration = 1;; ++iteration) {
    if (lambda == 0.0) lambda = std::max(dwarf, 0.001 * paru);
    if (!std::isfinite(lambda)) return nan;
    if (!cholesky_.factor(lambda) ||
        !((dxnorm = scaled_step()) < std::numeric_limits<double>::infinity())) {
      // (Rounding of a numerically singular J̃ᵀJ̃ above the base's floor: rare.)
      if (++failures > 40) return nan;
      floor_ = std::max(floor_, lambda);
      lambda = std::max(10.0 * lambda, regularising_lambda(largest_diagonal_));
      --iteration;
      continue;
    }
    const double previous = fp;
    fp = dxnorm - delta;
    if (std::abs(fp) <= 0.1 * delta || (parl == 0.0 && fp <= previous && previous < 0.0) ||
        iteration == 10) {
      step_in_x();
      return lambda;
    }
    // Newton correction of λ: φ' = −‖L⁻¹ P q‖² / ‖q‖.
    w_ = q_ / dxnorm;
    cholesky_.solve_lower(w_, y_);
    const double t = y_.norm();
    const double correction = ((fp / delta) / t) / t;
    if (fp > 0.0) parl = std::max(parl, lambda);
    if (fp < 0.0) paru = std::min(paru, lambda);
    const double next = std::max(parl, lambda + correction);
    if (fp < 0.0 && next <= floor_) {  // nothing smaller factors: this step is the shortest
      step_in_x();
      return lambda;
    }
    lambda = next;
  }
}

void LmNormalEquationsModel::multiply(const Vector<Dynamic>& p, Vector<Dynamic>& out) const {
  out.noalias() = jac_ * p;
}

void LmNormalEquationsModel::damped_solve(double lambda, Vector<Dynamic>& r, Vector<Dynamic>& a) {
  if (!valid_ || !std::isfinite(lambda)) {
    a.setConstant(std::numeric_limits<double>::quiet_NaN());
    return;
  }
  if (!cholesky_.factored() || cholesky_.lambda() != lambda) cholesky_.factor(lambda);
  // (J̃ᵀJ̃ + λI) q = −J̃ᵀ r, a = D⁻¹ q.
  rhs_.noalias() = jac_.transpose() * r;
  for (Index j = 0; j < rhs_.size(); ++j) {
    rhs_[j] = frozen_[static_cast<std::size_t>(j)] ? 0.0 : rhs_[j] / d_[j];
  }
  if (!cholesky_.factored()) {
    a.setConstant(std::numeric_limits<double>::quiet_NaN());
    return;
  }
  cholesky_.solve(rhs_, y_);
  a = -y_.cwiseQuotient(d_);
}

void LmNormalEquationsModel::report(Summary& summary) const {
  summary.linear_solver = "cholmod";
  summary.linear_setups = cholesky_.factorisations();
}

}  // namespace nlobs::detail
