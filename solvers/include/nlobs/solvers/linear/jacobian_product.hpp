#pragma once
// J v without J, for Jacobian-free Newton–Krylov [KK04]: the operator a KrylovSolver takes in
// setup(Operator, n). Set the linearisation point with at(x) (and F(x) for differences); each
// product then costs one evaluation of F.
//   AutodiffJacobianProduct: J v = d/dt F(x + t v) at t = 0, exactly, by one forward-mode AD
//     direction (ceres::Jet<double, 1>), for F generic in its scalar type.
//   DifferenceJacobianProduct: J v ≈ (F(x + σ v) − F(x)) / σ with KINSOL's step
//     σ = sign(xᵀv) · √ε · max(|xᵀv|, ‖v‖₁) / ‖v‖₂² (kinLsDQJtimes, unit scaling): relative to
//     the size of x along v, so that x + σ v changes x in about its √ε-th digits; ≈ √ε-accurate.
#include <ceres/jet.h>

#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "nlobs/common/invalid_input.hpp"
#include "nlobs/solvers/callable.hpp"
#include "nlobs/solvers/types.hpp"

namespace nlobs {

template <typename F>
class AutodiffJacobianProduct {
 public:
  // f: Rⁿ → Rᵐ generic in its scalar type (either shape of callable.hpp).
  explicit AutodiffJacobianProduct(F f) : f_(std::move(f)) {}

  void at(const Vector<Dynamic>& x) { x_ = x; }
  // jv = J(x) v; v of x's size.
  void operator()(const Vector<Dynamic>& v, Vector<Dynamic>& jv) {
    if (v.size() != x_.size()) {
      throw InvalidInput("AutodiffJacobianProduct: v has " + std::to_string(v.size()) +
                         " components, x " + std::to_string(x_.size()));
    }
    xj_.resize(x_.size());
    for (Index j = 0; j < x_.size(); ++j) {
      xj_[j].a = x_[j];
      xj_[j].v[0] = v[j];
    }
    detail::invoke_map(f_, xj_, fj_);
    jv.resize(fj_.size());
    for (Index i = 0; i < fj_.size(); ++i) jv[i] = fj_[i].v[0];
  }

 private:
  using Jet = ceres::Jet<double, 1>;
  F f_;
  Vector<Dynamic> x_;
  Vector<Dynamic, Jet> xj_, fj_;
};

template <typename F>
class DifferenceJacobianProduct {
 public:
  // f: Rⁿ → Rᵐ on doubles (either shape of callable.hpp).
  explicit DifferenceJacobianProduct(F f) : f_(std::move(f)) {}

  // The linearisation point and fx = F(x) (the engine has it already).
  void at(const Vector<Dynamic>& x, const Vector<Dynamic>& fx) {
    x_ = x;
    fx_ = fx;
  }
  int evaluations() const { return evaluations_; }

  void operator()(const Vector<Dynamic>& v, Vector<Dynamic>& jv) {
    if (v.size() != x_.size()) {
      throw InvalidInput("DifferenceJacobianProduct: v has " + std::to_string(v.size()) +
                         " components, x " + std::to_string(x_.size()));
    }
    const double v_norm2 = v.squaredNorm();
    if (v_norm2 == 0.0) {
      jv.setZero(fx_.size());
      return;
    }
    const double xv = x_.dot(v);
    const double sigma = (xv >= 0.0 ? 1.0 : -1.0) *
                         std::sqrt(std::numeric_limits<double>::epsilon()) *
                         std::max(std::abs(xv), v.lpNorm<1>()) / v_norm2;
    xt_ = x_ + sigma * v;
    detail::invoke_map(f_, xt_, jv);
    ++evaluations_;
    jv = (jv - fx_) / sigma;
  }

 private:
  F f_;
  Vector<Dynamic> x_, fx_, xt_;
  int evaluations_ = 0;
};

}  // namespace nlobs
