#include "nlobs/observers/core/interval_integrator.hpp"

#include <algorithm>
#include <boost/numeric/odeint.hpp>
#include <cmath>
#include <optional>

#include "nlobs/observers/core/option_checks.hpp"
#include "nlobs/observers/core/stiff_integrator.hpp"

namespace nlobs {
namespace {

namespace odeint = boost::numeric::odeint;
using State = std::vector<double>;

// Thrown through Odeint from F when it is not finite: the interval is abandoned there.
struct NotFinite {};

}  // namespace

std::string_view to_string(IntervalScheme scheme) {
  switch (scheme) {
    case IntervalScheme::kRk4:
      return "rk4";
    case IntervalScheme::kDopri5:
      return "dopri5";
    case IntervalScheme::kCvode:
      return "cvode";
  }
  return "unknown";
}

struct IntervalIntegrator::Impl {
  Rhs rhs;
  IntervalIntegratorOptions options;
  int size = 0;
  odeint::runge_kutta4<State> rk4;
  using Dopri5 = odeint::result_of::make_controlled<odeint::runge_kutta_dopri5<State>>::type;
  std::optional<Dopri5> dopri5;
  std::unique_ptr<StiffIntegrator> cvode;

  // Odeint's system signature over F; NotFinite aborts the interval.
  void system(const State& s, State& ds, double t) const {
    if (!rhs(t, s.data(), ds.data())) throw NotFinite{};
  }
};

IntervalIntegrator::IntervalIntegrator(int size, Rhs rhs, IntervalIntegratorOptions options,
                                       Jacobian jacobian)
    : impl_(std::make_unique<Impl>()) {
  constexpr const char* who = "IntervalIntegratorOptions";
  if (size < 0 || !rhs) throw InvalidInput("IntervalIntegrator: a size >= 0 and F required");
  detail::require_positive(who, "sample_time", options.sample_time);
  detail::require_at_least(who, "substeps", static_cast<long>(options.substeps), 1L);
  detail::require_positive(who, "absolute_tolerance", options.absolute_tolerance);
  detail::require_positive(who, "relative_tolerance", options.relative_tolerance);
  Impl& s = *impl_;
  s.rhs = std::move(rhs);
  s.options = options;
  s.size = size;
  // Odeint sizes its stages at the first step: do it here, so that no step allocates.
  const State shape(static_cast<size_t>(size), 0.0);
  if (options.scheme == IntervalScheme::kRk4) s.rk4.adjust_size(shape);
  if (options.scheme == IntervalScheme::kDopri5) {
    s.dopri5.emplace(odeint::make_controlled<odeint::runge_kutta_dopri5<State>>(
        options.absolute_tolerance, options.relative_tolerance));
    s.dopri5->adjust_size(shape);
  }
  if (options.scheme == IntervalScheme::kCvode && size > 0) {
    s.cvode = std::make_unique<StiffIntegrator>(
        size, s.rhs, std::move(jacobian), options.relative_tolerance, options.absolute_tolerance);
  }
}

IntervalIntegrator::~IntervalIntegrator() = default;

const IntervalIntegratorOptions& IntervalIntegrator::options() const {
  return impl_->options;
}

bool IntervalIntegrator::integrate(double t0, double t1, std::vector<double>& state,
                                   std::string* failure) {
  Impl& s = *impl_;
  if (s.size == 0) return true;  // nothing to integrate (a PI bank of signals only)
  const auto system = [&s](const State& x, State& dx, double t) { s.system(x, dx, t); };
  bool finite = true;
  switch (s.options.scheme) {
    case IntervalScheme::kRk4: {
      // After missing samples the interval spans several sample times: keep the step length.
      const long intervals = std::max(1L, std::lround((t1 - t0) / s.options.sample_time));
      const long steps = intervals * s.options.substeps;
      const double h = (t1 - t0) / static_cast<double>(steps);
      try {
        for (long i = 0; i < steps; ++i) {
          s.rk4.do_step(system, state, t0 + static_cast<double>(i) * h, h);
        }
      } catch (const NotFinite&) {
        finite = false;
      }
      break;
    }
    case IntervalScheme::kDopri5:
      s.dopri5->reset();  // FSAL: no derivative carried over from the last interval
      try {
        odeint::integrate_adaptive(*s.dopri5, system, state, t0, t1,
                                   s.options.sample_time / s.options.substeps);
      } catch (const NotFinite&) {
        finite = false;
      } catch (const odeint::step_adjustment_error&) {
        finite = false;
      }
      break;
    case IntervalScheme::kCvode:
      finite = s.cvode->integrate(t0, t1, state.data(), failure);
      break;
  }
  return finite;
}

}  // namespace nlobs
