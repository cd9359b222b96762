#pragma once
// Restarted GMRES(m) with right preconditioning [SS86; Saa03, §6.5 and §9.3.2], SUNDIALS'
// SPGMR: from x = 0, Arnoldi with modified Gram–Schmidt builds V_{k+1}, H̄_k with
// J M⁻¹ V_k = V_{k+1} H̄_k; Givens rotations keep H̄_k triangular, so that |g_{k+1}| is
// ‖b − J x_k‖₂ at no cost; after m steps (or on meeting the tolerance) x += M⁻¹ V_k y_k,
// y_k = argmin ‖β e₁ − H̄_k y‖₂, and the true residual restarts the next cycle.
//
// A new Arnoldi vector of norm ≤ ε × that of J M⁻¹ v_k before orthogonalisation ends the cycle
// (the Krylov space is invariant to rounding: the "lucky" breakdown, x is as good as this space
// allows). Named failures: kBreakdown when H̄_k's triangular factor has a diagonal
// ≤ kSingularPivot (1e-13, the direct solvers' rule) × its column's norm (J M⁻¹ singular on the
// Krylov space: b outside J's range),
// kNotConverged when max_iterations Arnoldi steps (over all cycles) leave ‖b − J x‖₂ above the
// tolerance, kNonFinite when J v or M⁻¹ r is not. At most n vectors per cycle are kept, whatever
// `restart` says: more cannot be independent.
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>

#include "nlobs/solvers/linear/krylov_solver.hpp"

namespace nlobs {

struct GmresOptions {
  int restart = 30;          // m: Krylov vectors per cycle, ≥ 1 (memory (m + 1)·n)
  int max_iterations = 300;  // Arnoldi steps over all cycles, ≥ 1
};

class GmresSolver final : public KrylovSolver {
 public:
  explicit GmresSolver(GmresOptions options = {},
                       std::unique_ptr<LinearPreconditioner> preconditioner = nullptr)
      : KrylovSolver(std::move(preconditioner)), options_(options) {
    if (options_.restart < 1) {
      throw InvalidInput("GmresOptions::restart = " + std::to_string(options_.restart) +
                         " must be >= 1");
    }
    if (options_.max_iterations < 1) {
      throw InvalidInput("GmresOptions::max_iterations = " +
                         std::to_string(options_.max_iterations) + " must be >= 1");
    }
  }
  std::string_view name() const override { return "gmres"; }
  const GmresOptions& options() const { return options_; }

  LinearStatus solve(const Vector<Dynamic>& b, Vector<Dynamic>& x, double tolerance) override {
    ++stats_.solves;
    if (const LinearStatus s = check_right_hand_side(b); s != LinearStatus::kSolved) return s;
    if (const LinearStatus s = check_tolerance(tolerance); s != LinearStatus::kSolved) return s;
    const Index n = b.size();
    const int m = static_cast<int>(std::min<Index>(options_.restart, n));
    if (basis_.rows() != n || basis_.cols() != m + 1) basis_.resize(n, m + 1);
    hessenberg_.resize(m + 1, m);
    cosine_.resize(m);
    sine_.resize(m);
    g_.resize(m + 1);
    y_.resize(m);
    rhs_ = b;  // before x is written: x may be b
    x.setZero(n);
    const double b_norm = rhs_.norm();
    stats_.last_residual = b_norm == 0.0 ? 0.0 : 1.0;  // ‖b − J·0‖ / ‖b‖
    if (b_norm == 0.0) return succeed();
    const double target = tolerance * b_norm;
    residual_ = rhs_;
    double beta = b_norm;
    int iterations = 0;
    for (;;) {
      basis_.col(0) = residual_ / beta;
      g_.setZero();
      g_[0] = beta;
      int k = 0;  // Arnoldi steps in this cycle
      while (k < m && iterations < options_.max_iterations) {
        v_ = basis_.col(k);  // a vector, not a column view: no temporary per step
        if (!precondition(v_, z_) || !multiply(z_, w_)) return give_up(iterations);
        const double before = w_.norm();
        for (int i = 0; i <= k; ++i) {  // modified Gram–Schmidt
          hessenberg_(i, k) = w_.dot(basis_.col(i));
          w_ -= hessenberg_(i, k) * basis_.col(i);
        }
        double next = w_.norm();
        const bool invariant = next <= kEpsilon * before;
        if (invariant) next = 0.0;
        hessenberg_(k + 1, k) = next;
        for (int i = 0; i < k; ++i) rotate(i, hessenberg_(i, k), hessenberg_(i + 1, k));
        const double a = hessenberg_(k, k), c = hessenberg_(k + 1, k);
        const double r = std::hypot(a, c);
        if (!(r > kSingularPivot * hessenberg_.col(k).head(k + 2).norm()) || before == 0.0) {
          return breakdown(iterations + 1);
        }
        cosine_[k] = r > 0.0 ? a / r : 1.0;
        sine_[k] = r > 0.0 ? c / r : 0.0;
        hessenberg_(k, k) = r;
        hessenberg_(k + 1, k) = 0.0;
        rotate(k, g_[k], g_[k + 1]);
        ++k;
        ++iterations;
        ++stats_.iterations;
        if (std::abs(g_[k]) <= target || invariant) break;
        basis_.col(k) = w_ / next;
      }
      for (int i = k - 1; i >= 0; --i) {  // y = R_k⁻¹ g_k (R_k's diagonal checked above)
        double sum = g_[i];
        for (int j = i + 1; j < k; ++j) sum -= hessenberg_(i, j) * y_[j];
        y_[i] = sum / hessenberg_(i, i);
      }
      w_.noalias() = basis_.leftCols(k) * y_.head(k);
      if (!precondition(w_, z_)) return give_up(iterations);
      x += z_;
      if (!multiply(x, w_)) return give_up(iterations);
      residual_ = rhs_ - w_;
      beta = residual_.norm();
      stats_.last_residual = beta / b_norm;
      if (beta <= target) return succeed();
      if (iterations >= options_.max_iterations) {
        std::ostringstream os;
        os << "no convergence in " << iterations
           << " iterations: |b - J x| / |b| = " << stats_.last_residual << " > " << tolerance;
        return fail(LinearStatus::kNotConverged, os.str());
      }
    }
  }

 private:
  static constexpr double kEpsilon = std::numeric_limits<double>::epsilon();

  LinearStatus breakdown(int iterations) {
    std::ostringstream os;
    os << "breakdown at iteration " << iterations
       << ": J M^-1 is singular on the Krylov space (b outside J's range?)";
    return fail(LinearStatus::kBreakdown, os.str());
  }
  // Apply rotation i to the pair (p, q).
  void rotate(int i, double& p, double& q) const {
    const double t = cosine_[i] * p + sine_[i] * q;
    q = -sine_[i] * p + cosine_[i] * q;
    p = t;
  }
  // After multiply() or precondition() failed (recorded as kNonFinite).
  LinearStatus give_up(int iterations) {
    message_ += " (after " + std::to_string(iterations) + " iterations)";
    return LinearStatus::kNonFinite;
  }

  GmresOptions options_;
  Matrix<Dynamic, Dynamic> basis_, hessenberg_;
  Vector<Dynamic> cosine_, sine_, g_, y_, residual_, rhs_, v_, w_, z_;
};

}  // namespace nlobs
