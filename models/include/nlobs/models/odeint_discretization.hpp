#pragma once
// Adaptive integration between samples through Boost.Odeint (no integrator of our own):
// x⁺ = φ(t_{k+1}; t_k, x_k, u_k) with the controlled Dormand–Prince 5(4) stepper, absolute
// and relative tolerances as options. Evaluated in double only — estimators that need ∂f use
// finite differences on it, or the fixed-step Discretized for AD. For stiff systems, the
// Rosenbrock stepper arrives with the high-gain observer (issue 6), which needs it.
#include <algorithm>
#include <boost/numeric/odeint.hpp>
#include <cmath>
#include <sstream>
#include <vector>

#include "nlobs/common/invalid_input.hpp"
#include "nlobs/models/discretization.hpp"

namespace nlobs {

struct OdeintOptions {
  double absolute_tolerance = 1e-10;
  double relative_tolerance = 1e-10;
};

template <ContinuousModel Model>
class OdeintDiscretized : public SampledModel<Model> {
 public:
  static constexpr bool kTracesSparsity = false;  // evaluated in double only
  using typename SampledModel<Model>::Input;
  template <typename T>
  using State = typename SampledModel<Model>::template State<T>;

  OdeintDiscretized(Model model, double step, OdeintOptions options = {})
      : SampledModel<Model>(std::move(model), step), options_(options) {
    const auto check = [](const char* field, double value) {
      if (value > 0.0 && std::isfinite(value)) return;
      std::ostringstream os;
      os << "OdeintOptions::" << field << " must be finite and > 0 (got " << value << ")";
      throw InvalidInput(os.str());
    };
    check("absolute_tolerance", options_.absolute_tolerance);
    check("relative_tolerance", options_.relative_tolerance);
  }

  template <typename T>
  State<T> f(const State<T>& x, const Input& u, long k) const {
    return flow(x, u, static_cast<double>(k) * this->step_, this->step_);
  }

  // x(t + dt) from x(t), u held, dt ≥ 0 (x itself for dt = 0); throws InvalidInput for a dt that
  // is not finite.
  template <typename T>
  State<T> flow(const State<T>& x, const Input& u, double t, double dt) const {
    static_assert(std::is_same_v<T, double>,
                  "OdeintDiscretized is evaluated in double only (use Discretized for AD)");
    namespace odeint = boost::numeric::odeint;
    using Buffer = std::vector<double>;
    if (!std::isfinite(dt)) throw InvalidInput("OdeintDiscretized::flow: dt is not finite");
    if (!(dt > 0.0)) return x;
    Buffer state(x.data(), x.data() + x.size());
    const auto rhs = [this, &u](const Buffer& s, Buffer& ds, double time) {
      const State<double> xs =
          Eigen::Map<const State<double>>(s.data(), static_cast<Eigen::Index>(s.size()));
      const State<double> d = this->model_.vector_field(xs, u, time);
      ds.assign(d.data(), d.data() + d.size());
    };
    odeint::integrate_adaptive(odeint::make_controlled<odeint::runge_kutta_dopri5<Buffer>>(
                                   options_.absolute_tolerance, options_.relative_tolerance),
                               rhs, state, t, t + dt, std::min(dt, this->step_) / 10.0);
    return Eigen::Map<const State<double>>(state.data(), x.size());
  }

 private:
  OdeintOptions options_;
};

}  // namespace nlobs
