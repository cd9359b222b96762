#pragma once
// Classic fourth-order Runge–Kutta steps (Boost.Odeint's runge_kutta4) on a state whose size is
// known at run time, compiled once in the observers library: an observer of any model steps
// through it instead of instantiating Odeint's stepper in every file that includes it (the
// high-gain observer: ẑ and the prediction x̄ in one std::vector). No allocation after the
// first step at a given size.
#include <functional>
#include <memory>
#include <vector>

namespace nlobs {

class Rk4Stepper {
 public:
  // ds = F(t, s); ds has the size of s.
  using Rhs = std::function<void(double t, const std::vector<double>& s, std::vector<double>& ds)>;

  Rk4Stepper();
  ~Rk4Stepper();
  Rk4Stepper(const Rk4Stepper&) = delete;
  Rk4Stepper& operator=(const Rk4Stepper&) = delete;

  // state(t) → state(t + h) in place.
  void step(const Rhs& rhs, std::vector<double>& state, double t, double h);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace nlobs
