#pragma once
// BiCGSTAB with right preconditioning [vdV92; Saa03, Algorithm 7.7]: two products J v and two
// applications of M⁻¹ per iteration, memory 7n whatever the iteration count (GMRES keeps m + 1
// vectors), a residual that need not fall monotonically. The recurrence's residual drifts from
// the true one; a solve ends only when the true ‖b − J x‖₂ meets the tolerance, else the
// recurrence restarts from the true residual.
//
// Named failures: kBreakdown when ρ = (r̂₀, r) or (r̂₀, J p̂) vanishes (relative to the vectors'
// norms, below ε²: the shadow residual became orthogonal) or ω does (|(J ŝ, s)| ≤ ε ‖J ŝ‖ ‖s‖:
// the minimal-residual step stalls), kNotConverged when max_iterations pass above the tolerance,
// kNonFinite as GMRES.
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>

#include "nlobs/solvers/linear/krylov_solver.hpp"

namespace nlobs {

struct BicgstabOptions {
  int max_iterations = 300;  // ≥ 1 (each costs two J v and two M⁻¹ r)
};

class BicgstabSolver final : public KrylovSolver {
 public:
  explicit BicgstabSolver(BicgstabOptions options = {},
                          std::unique_ptr<LinearPreconditioner> preconditioner = nullptr)
      : KrylovSolver(std::move(preconditioner)), options_(options) {
    if (options_.max_iterations < 1) {
      throw InvalidInput("BicgstabOptions::max_iterations = " +
                         std::to_string(options_.max_iterations) + " must be >= 1");
    }
  }
  std::string_view name() const override { return "bicgstab"; }
  const BicgstabOptions& options() const { return options_; }

  LinearStatus solve(const Vector<Dynamic>& b, Vector<Dynamic>& x, double tolerance) override {
    ++stats_.solves;
    if (const LinearStatus s = check_right_hand_side(b); s != LinearStatus::kSolved) return s;
    if (const LinearStatus s = check_tolerance(tolerance); s != LinearStatus::kSolved) return s;
    const Index n = b.size();
    rhs_ = b;  // before x is written: x may be b
    x.setZero(n);
    const double b_norm = rhs_.norm();
    stats_.last_residual = b_norm == 0.0 ? 0.0 : 1.0;  // ‖b − J·0‖ / ‖b‖
    if (b_norm == 0.0) return succeed();
    const double target = tolerance * b_norm;
    const double epsilon = std::numeric_limits<double>::epsilon();
    const double tiny = epsilon * epsilon;
    r_ = rhs_;
    int iterations = 0;
    while (iterations < options_.max_iterations) {
      // A cycle of the recurrence from the residual r_ of the current x.
      shadow_ = r_;
      double rho_old = 1.0, alpha = 1.0, omega = 1.0;
      v_.setZero(n);
      p_.setZero(n);
      while (iterations < options_.max_iterations) {
        ++iterations;
        ++stats_.iterations;
        const double rho = shadow_.dot(r_);
        if (std::abs(rho) <= tiny * shadow_.norm() * r_.norm()) {
          return breakdown(iterations, "rho = (r0, r) vanished");
        }
        const double beta = (rho / rho_old) * (alpha / omega);
        p_ = r_ + beta * (p_ - omega * v_);
        if (!precondition(p_, p_hat_) || !multiply(p_hat_, v_)) return give_up(iterations);
        const double shadow_v = shadow_.dot(v_);
        if (std::abs(shadow_v) <= tiny * shadow_.norm() * v_.norm()) {
          return breakdown(iterations, "(r0, J p) vanished");
        }
        alpha = rho / shadow_v;
        s_ = r_ - alpha * v_;
        if (s_.norm() <= target) {
          x += alpha * p_hat_;
          break;  // checked against the true residual below
        }
        if (!precondition(s_, s_hat_) || !multiply(s_hat_, t_)) return give_up(iterations);
        const double ts = t_.dot(s_);
        if (!(std::abs(ts) > epsilon * t_.norm() * s_.norm())) {
          return breakdown(iterations, "omega = (J s, s) / |J s|^2 vanished (J s orthogonal to s)");
        }
        omega = ts / t_.squaredNorm();
        x += alpha * p_hat_ + omega * s_hat_;
        r_ = s_ - omega * t_;
        rho_old = rho;
        if (r_.norm() <= target) break;
      }
      if (!multiply(x, t_)) return give_up(iterations);
      r_ = rhs_ - t_;
      stats_.last_residual = r_.norm() / b_norm;
      if (r_.norm() <= target) return succeed();
    }
    std::ostringstream os;
    os << "no convergence in " << iterations
       << " iterations: |b - J x| / |b| = " << stats_.last_residual << " > " << tolerance;
    return fail(LinearStatus::kNotConverged, os.str());
  }

 private:
  LinearStatus breakdown(int iterations, const char* what) {
    std::ostringstream os;
    os << "breakdown at iteration " << iterations << ": " << what;
    return fail(LinearStatus::kBreakdown, os.str());
  }
  // After multiply() or precondition() failed (recorded as kNonFinite).
  LinearStatus give_up(int iterations) {
    message_ += " (at iteration " + std::to_string(iterations) + ")";
    return LinearStatus::kNonFinite;
  }

  BicgstabOptions options_;
  Vector<Dynamic> rhs_, r_, shadow_, v_, p_, p_hat_, s_, s_hat_, t_;
};

}  // namespace nlobs
