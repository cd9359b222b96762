#pragma once
// What a ModulatingFunctionObserver needs from a system ([MF-LTV]): its input–output equation
// in the right-PDO form of the observability companion form (OCF),
//   y⁽ⁿ⁾ + Σ_{i<n} (a_i(t) y)⁽ⁱ⁾ = Σ_{i<n} (b_i(t)ᵀ v)⁽ⁱ⁾,   v = v(t, y, u) known,
// whose canonical state η (η_{n−1} = y) obeys
//   η_j' = η_{j−1} − a_j(t) y + b_j(t)ᵀ v,   η_{−1} = 0,
// and the change of coordinates to the model's state x (the paper's Remark 2). A form is a
// small type (Vector<k> = Eigen::Matrix<double, k, 1>, Matrix<r, c> = Eigen::Matrix<double, r, c>):
//   static constexpr int n, p, state_size;                  // order, |v|, |x|
//   void coefficients(double t, Vector<n>& a, Matrix<n, p>& b) const;   // a_i(t), rows b_iᵀ(t)
//   Vector<p> inputs(double t, double y, const Eigen::VectorXd& u) const;  // v
//   Vector<n> canonical(double t, const Vector<state_size>& x) const;      // η(t, x)
//   Vector<state_size> state(double t, const Vector<n>& eta) const;        // x(t, η)
// and, when an unknown disturbance d enters the canonical equations, its gains and bound:
//   Vector<n> disturbance_gains() const;  double disturbance_level() const;   // |d| ≤ level
#include <Eigen/Core>
#include <cmath>

#include "nlobs/models/systems.hpp"

namespace nlobs {

// x1' = x2, x2' = −a0 x1 − a1 x2 + gain sin y, y = x1: y'' + a1 y' + a0 y = gain · sin y,
// so a = (a0, a1), b_0 = gain, v = sin y; η_1 = y, η_0 = y' + a1 y.
struct LtiInjectionForm {
  static constexpr int n = 2, p = 1, state_size = 2;
  LtiInjectionParameters params{};
  void coefficients(double, Eigen::Matrix<double, 2, 1>& a, Eigen::Matrix<double, 2, 1>& b) const {
    a << params.a0, params.a1;
    b << params.gain, 0.0;
  }
  Eigen::Matrix<double, 1, 1> inputs(double, double y, const Eigen::VectorXd&) const {
    return Eigen::Matrix<double, 1, 1>(std::sin(y));
  }
  Eigen::Matrix<double, 2, 1> canonical(double, const Eigen::Matrix<double, 2, 1>& x) const {
    return Eigen::Matrix<double, 2, 1>(x[1] + params.a1 * x[0], x[0]);
  }
  Eigen::Matrix<double, 2, 1> state(double, const Eigen::Matrix<double, 2, 1>& eta) const {
    return Eigen::Matrix<double, 2, 1>(eta[1], eta[0] - params.a1 * eta[1]);
  }
};

// The pendulum with friction c(t): y'' + c(t) y' = −(g/l) sin y + d(t), d = −(a(t)/l) cos y the
// unknown disturbance. Since c y' = (c y)' − c' y: a_1 = c(t), a_0 = −c'(t), b_0 = −g/l,
// v = sin y; η_1 = y, η_0 = y' + c(t) y (time-varying coordinates). d enters η_0' with gain 1.
struct PendulumForm {
  static constexpr int n = 2, p = 1, state_size = 2;
  PendulumParameters params{};
  double friction(double t) const { return params.c0 + params.c1 * std::sin(params.omega_c * t); }
  double friction_rate(double t) const {
    return params.c1 * params.omega_c * std::cos(params.omega_c * t);
  }
  void coefficients(double t, Eigen::Matrix<double, 2, 1>& a,
                    Eigen::Matrix<double, 2, 1>& b) const {
    a << -friction_rate(t), friction(t);
    b << -params.g / params.length, 0.0;
  }
  Eigen::Matrix<double, 1, 1> inputs(double, double y, const Eigen::VectorXd&) const {
    return Eigen::Matrix<double, 1, 1>(std::sin(y));
  }
  Eigen::Matrix<double, 2, 1> canonical(double t, const Eigen::Matrix<double, 2, 1>& x) const {
    return Eigen::Matrix<double, 2, 1>(x[1] + friction(t) * x[0], x[0]);
  }
  Eigen::Matrix<double, 2, 1> state(double t, const Eigen::Matrix<double, 2, 1>& eta) const {
    return Eigen::Matrix<double, 2, 1>(eta[1], eta[0] - friction(t) * eta[1]);
  }
  // |d| ≤ a_max / l, entering η_0' with gain 1 (disturbance_gains).
  double disturbance_level() const { return std::abs(params.a_max) / params.length; }
  Eigen::Matrix<double, 2, 1> disturbance_gains() const { return {1.0, 0.0}; }
};

// The customisation point the model registry looks for (nlobs/registry/register_model.hpp):
// a model that has a function modulating_form(const Model&), found by argument-dependent
// lookup, can run the modulating-function observer from scenario files.
inline LtiInjectionForm modulating_form(const LtiOutputInjection& model) {
  return {model.p};
}
inline PendulumForm modulating_form(const PendulumTimeVaryingFriction& model) {
  return {model.p};
}

}  // namespace nlobs
