#pragma once
// Modified Chua attractor (METHODS §1, paper eqs. 77–78), discretised by forward Euler:
//   x1' = α (x2 + b sin(π x1 / (2a) + d))
//   x2' = x1 − x2 + x3
//   x3' = −β x2,                y = x1
//   x⁺ = x + T · F(x)           (the paper's contraction analysis needs T ∈ (0, 2/α))
// Functions are templated on the scalar so that solvers can differentiate them (AD).
#include <Eigen/Core>
#include <cmath>
#include <numbers>

namespace nlobs {

struct ModifiedChuaParameters {
  double alpha = 10.82;
  double beta = 14.286;
  double a = 1.3;
  double b = 0.11;
  double d = 1.0;
  double sampling_time = 0.05;  // T
};

class ModifiedChua {
 public:
  static constexpr int kStates = 3;
  static constexpr int kOutputs = 1;
  template <typename T>
  using State = Eigen::Matrix<T, kStates, 1>;
  template <typename T>
  using Output = Eigen::Matrix<T, kOutputs, 1>;

  // Throws std::invalid_argument naming the parameter when a value is non-finite, a = 0 or T ≤ 0.
  explicit ModifiedChua(ModifiedChuaParameters parameters = {});
  const ModifiedChuaParameters& parameters() const { return p_; }

  // Continuous vector field F(x).
  template <typename T>
  State<T> vector_field(const State<T>& x) const {
    using std::sin;
    State<T> dx;
    dx[0] = p_.alpha * (x[1] + p_.b * sin(k_ * x[0] + p_.d));
    dx[1] = x[0] - x[1] + x[2];
    dx[2] = -p_.beta * x[1];
    return dx;
  }
  // Discrete map f(x) = x + T F(x) (eq. 78).
  template <typename T>
  State<T> f(const State<T>& x) const {
    return x + p_.sampling_time * vector_field(x);
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return x.template head<1>();
  }

 private:
  ModifiedChuaParameters p_;
  double k_;  // π / (2a), kept so that an evaluation divides nothing
};

}  // namespace nlobs
