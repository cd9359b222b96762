#pragma once
// The one integrator of the observers that run continuous dynamics between samples (MVT,
// high-gain, PI bank): s(t0) → s(t1) for s' = F(t, s) on a state whose size is known at run
// time, by one of three schemes chosen here and nowhere else —
//   kRk4    classic Runge–Kutta (Boost.Odeint's runge_kutta4), `substeps` steps per sample
//           interval; an interval that spans several sample times (after missing samples) keeps
//           the step length;
//   kDopri5 adaptive Dormand–Prince 5(4) (Boost.Odeint, controlled, FSAL restarted per call),
//           first step T / substeps, absolute and relative tolerances;
//   kCvode  SUNDIALS CVODE, BDF with a dense solver (stiff_integrator.hpp), the caller's
//           Jacobian or CVODE's difference quotients when none is given.
// Compiled once in the observers library (src/core/interval_integrator.cpp), so no observer
// instantiates Odeint in the files that include it. Nothing allocates after construction
// (RK4, Dormand–Prince; CVODE's own workspace is allocated when it is set up).
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace nlobs {

enum class IntervalScheme { kRk4, kDopri5, kCvode };

std::string_view to_string(IntervalScheme scheme);  // "rk4", "dopri5", "cvode"

struct IntervalIntegratorOptions {
  IntervalScheme scheme = IntervalScheme::kRk4;
  double sample_time = 0.0;           // T > 0: the intervals' nominal length
  int substeps = 1;                   // kRk4: steps per T; kDopri5: first step T / substeps
  double absolute_tolerance = 1e-10;  // kDopri5, kCvode
  double relative_tolerance = 1e-10;  // kDopri5, kCvode
};

class IntervalIntegrator {
 public:
  // ds = F(t, s); false when F is not finite at (t, s): the interval is then abandoned.
  using Rhs = std::function<bool(double t, const double* s, double* ds)>;
  // J = ∂F/∂s at (t, s), column-major size × size (kCvode; empty: difference quotients).
  using Jacobian = std::function<void(double t, const double* s, double* jacobian)>;

  // Throws InvalidInput for a size < 0, no F, T not finite and > 0, substeps < 1, tolerances
  // not finite and > 0.
  IntervalIntegrator(int size, Rhs rhs, IntervalIntegratorOptions options, Jacobian jacobian = {});
  ~IntervalIntegrator();
  IntervalIntegrator(const IntervalIntegrator&) = delete;
  IntervalIntegrator& operator=(const IntervalIntegrator&) = delete;

  // state(t0) → state(t1) in place. False when F was not finite on the way (the state is then
  // unspecified: pass a copy), with CVODE's reason in `failure` when it gives one (untouched
  // otherwise). Whether the state at t1 is finite is the caller's to judge (the high-gain
  // observer tolerates a blown-up prediction beside a finite ẑ).
  bool integrate(double t0, double t1, std::vector<double>& state, std::string* failure = nullptr);

  const IntervalIntegratorOptions& options() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace nlobs
