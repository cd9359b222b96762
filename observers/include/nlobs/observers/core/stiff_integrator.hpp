#pragma once
// Implicit integration for stiff observer dynamics (high gains): SUNDIALS CVODE, BDF with a
// dense direct solver and the caller's Jacobian. Boost.Odeint's Rosenbrock stepper would be
// the header-only choice, but it needs Boost.uBLAS, whose storage does not compile as C++20 in
// Boost 1.74 (Debian 12). Restarted at every call: observers reset part of their state between
// samples, and a BDF history across that reset would be wrong.
#include <functional>
#include <memory>
#include <string>

namespace nlobs {

class StiffIntegrator {
 public:
  // ds = F(t, s); false when F is not finite at s.
  using Rhs = std::function<bool(double t, const double* s, double* ds)>;
  // J = ∂F/∂s at (t, s), column-major size × size; empty: CVODE's difference quotients.
  using Jacobian = std::function<void(double t, const double* s, double* jacobian)>;

  StiffIntegrator(int size, Rhs rhs, Jacobian jacobian, double relative_tolerance,
                  double absolute_tolerance);
  ~StiffIntegrator();
  StiffIntegrator(const StiffIntegrator&) = delete;
  StiffIntegrator& operator=(const StiffIntegrator&) = delete;

  // state(t0) → state(t1) in place. False, state untouched, with the reason in `failure`.
  bool integrate(double t0, double t1, double* state, std::string* failure);
  long steps() const;  // internal steps of the last call

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace nlobs
