#include "nlobs/observers/rk4_stepper.hpp"

#include <boost/numeric/odeint/stepper/runge_kutta4.hpp>

namespace nlobs {

struct Rk4Stepper::Impl {
  boost::numeric::odeint::runge_kutta4<std::vector<double>> stepper;
};

Rk4Stepper::Rk4Stepper() : impl_(std::make_unique<Impl>()) {}
Rk4Stepper::~Rk4Stepper() = default;

void Rk4Stepper::step(const Rhs& rhs, std::vector<double>& state, double t, double h) {
  impl_->stepper.do_step(
      [&rhs](const std::vector<double>& s, std::vector<double>& ds, double at) { rhs(at, s, ds); },
      state, t, h);
}

}  // namespace nlobs
