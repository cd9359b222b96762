#pragma once
// Modified Chua attractor ([MGFF23], paper eqs. 77–78):
//   x1' = α (x2 + b sin(π x1 / (2a) + d))
//   x2' = x1 − x2 + x3
//   x3' = −β x2,                y = x1
// The paper observes its forward-Euler discretisation with T = 0.05 (its contraction analysis
// needs T ∈ (0, 2/α)): paper_modified_chua().
#include <cmath>
#include <numbers>

#include "nlobs/models/discretization.hpp"

namespace nlobs {

struct ModifiedChuaParameters {
  double alpha = 10.82;
  double beta = 14.286;
  double a = 1.3;
  double b = 0.11;
  double d = 1.0;
};

class ModifiedChua : public ModelSizes<3, 0, 1> {
 public:
  // Throws InvalidInput naming the parameter when a value is non-finite or a = 0.
  explicit ModifiedChua(ModifiedChuaParameters parameters = {});
  const ModifiedChuaParameters& parameters() const { return p_; }

  template <typename T>
  State<T> vector_field(const State<T>& x, const Input& /*u*/, double /*t*/) const {
    using std::sin;
    State<T> dx;
    dx[0] = p_.alpha * (x[1] + p_.b * sin(k_ * x[0] + p_.d));
    dx[1] = x[0] - x[1] + x[2];
    dx[2] = -p_.beta * x[1];
    return dx;
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return x.template head<1>();
  }

 private:
  ModifiedChuaParameters p_;
  double k_;  // π / (2a), kept so that an evaluation divides nothing
};

// The paper's discrete model: forward Euler with T = 0.05.
inline Discretized<ModifiedChua> paper_modified_chua(ModifiedChuaParameters p = {},
                                                     double sampling_time = 0.05) {
  return Discretized<ModifiedChua>(ModifiedChua(p), sampling_time, Scheme::kEuler);
}

}  // namespace nlobs
