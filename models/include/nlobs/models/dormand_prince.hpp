#pragma once
// Adaptive explicit integration generic in the scalar: the Dormand–Prince 5(4) pair [DP80] with
// the standard step-size control of [HNW93] §II.4, so that the EKF, the MHE and the windows
// differentiate an error-controlled flow by AD as they do the fixed steps. Each step's local
// error estimate, err = ‖h Σ e_j k_j / (atol + rtol max(|x|, |x⁺|))‖_RMS, and every decision
// taken from it use the values of the scalars (scalar_value.hpp): on AD scalars the steps are
// those taken on doubles, and the derivative is the method's with those steps fixed.
//   accept when err ≤ 1; next h = h min(5, max(0.2, 0.9 err^(−1/5))) (no growth right after a
//   rejection), never above the largest step;
//   refuse (IntegrationFailure) when h falls below 1e-12 of min(largest step, dt) — the plant
//   is too stiff there for an explicit scheme, or the state has left the model's range — or
//   when 100 000 attempts more than twice the ⌈dt / largest step⌉ the interval needs at least
//   do not reach its end.
// A state or vector field that is not finite at a step's start is not integrated further: the
// result is not finite, for the caller to judge as after an explicit step that overflowed.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "nlobs/models/integration_failure.hpp"
#include "nlobs/models/model.hpp"
#include "nlobs/models/scalar_value.hpp"

namespace nlobs {

struct AdaptiveStepControl {
  static constexpr double kSpareAttempts = 100000;  // beyond 2 ⌈dt / largest_step⌉ per call
  double largest_step = 0.0;                        // > 0: also the first step tried
  double absolute_tolerance = 1e-8;
  double relative_tolerance = 1e-6;
};

// x(t + dt) from x(t), u held, 0 ≤ dt finite (checked by the caller).
template <ContinuousModel Model, typename T>
ModelVector<T, Model::kStates> dormand_prince_flow(const Model& model,
                                                   const ModelVector<T, Model::kStates>& x,
                                                   const ModelVector<double, Model::kInputs>& u,
                                                   double t, double dt,
                                                   const AdaptiveStepControl& control) {
  using State = ModelVector<T, Model::kStates>;
  // [DP80], Table 2 (as [HNW93] Table II.5.2 prints it): stages, 5th-order weights b (the last
  // row of a: first same as last) and e = b − b̂, b̂ the embedded 4th-order weights.
  constexpr double c2 = 1.0 / 5, c3 = 3.0 / 10, c4 = 4.0 / 5, c5 = 8.0 / 9;
  constexpr double a21 = 1.0 / 5;
  constexpr double a31 = 3.0 / 40, a32 = 9.0 / 40;
  constexpr double a41 = 44.0 / 45, a42 = -56.0 / 15, a43 = 32.0 / 9;
  constexpr double a51 = 19372.0 / 6561, a52 = -25360.0 / 2187, a53 = 64448.0 / 6561,
                   a54 = -212.0 / 729;
  constexpr double a61 = 9017.0 / 3168, a62 = -355.0 / 33, a63 = 46732.0 / 5247, a64 = 49.0 / 176,
                   a65 = -5103.0 / 18656;
  constexpr double b1 = 35.0 / 384, b3 = 500.0 / 1113, b4 = 125.0 / 192, b5 = -2187.0 / 6784,
                   b6 = 11.0 / 84;
  constexpr double e1 = 71.0 / 57600, e3 = -71.0 / 16695, e4 = 71.0 / 1920, e5 = -17253.0 / 339200,
                   e6 = 22.0 / 525, e7 = -1.0 / 40;

  if (!(dt > 0.0)) return x;
  const Eigen::Index n = x.size();
  const double floor = 1e-12 * std::min(control.largest_step, dt);
  State y = x;
  State k1 = model.vector_field(y, u, t);
  double elapsed = 0.0, h = std::min(control.largest_step, dt), err = 0.0;
  const double most_attempts =
      AdaptiveStepControl::kSpareAttempts + 2.0 * std::ceil(dt / control.largest_step);
  bool rejected = false;
  for (double attempts = 0; elapsed < dt; ++attempts) {
    const double now = t + elapsed;
    bool finite = true;
    for (Eigen::Index i = 0; i < n && finite; ++i) {
      finite = std::isfinite(scalar_value(y[i])) && std::isfinite(scalar_value(k1[i]));
    }
    if (!finite) return State(y + (dt - elapsed) * k1);
    if (h < floor) {
      std::ostringstream os;
      os << "dopri5: the step fell to " << h << " at t = " << now << " (local error " << err
         << " of the tolerance): the plant is too stiff here for an explicit scheme (scheme "
            "sdirk3) or its state has left the model's range";
      throw IntegrationFailure(os.str());
    }
    if (attempts >= most_attempts) {
      std::ostringstream os;
      os << "dopri5: " << attempts << " attempted steps reached t = " << now << " of [" << t << ", "
         << t + dt << "], the last of length " << h
         << ": the error control needs steps far below h / substeps = " << control.largest_step
         << " over this interval (a stiff plant: scheme sdirk3)";
      throw IntegrationFailure(os.str());
    }
    const bool last = elapsed + h >= dt;
    if (last) h = dt - elapsed;
    const State k2 = model.vector_field(State(y + h * a21 * k1), u, now + c2 * h);
    const State k3 = model.vector_field(State(y + h * (a31 * k1 + a32 * k2)), u, now + c3 * h);
    const State k4 =
        model.vector_field(State(y + h * (a41 * k1 + a42 * k2 + a43 * k3)), u, now + c4 * h);
    const State k5 = model.vector_field(State(y + h * (a51 * k1 + a52 * k2 + a53 * k3 + a54 * k4)),
                                        u, now + c5 * h);
    const State k6 = model.vector_field(
        State(y + h * (a61 * k1 + a62 * k2 + a63 * k3 + a64 * k4 + a65 * k5)), u, now + h);
    const State next = y + h * (b1 * k1 + b3 * k3 + b4 * k4 + b5 * k5 + b6 * k6);
    const State k7 = model.vector_field(next, u, now + h);
    double sum = 0.0;
    for (Eigen::Index i = 0; i < n; ++i) {
      const double e =
          h * (e1 * scalar_value(k1[i]) + e3 * scalar_value(k3[i]) + e4 * scalar_value(k4[i]) +
               e5 * scalar_value(k5[i]) + e6 * scalar_value(k6[i]) + e7 * scalar_value(k7[i]));
      const double scale = control.absolute_tolerance +
                           control.relative_tolerance * std::max(std::abs(scalar_value(y[i])),
                                                                 std::abs(scalar_value(next[i])));
      sum += (e / scale) * (e / scale);
    }
    err = std::sqrt(sum / static_cast<double>(std::max<Eigen::Index>(n, 1)));
    if (!(err <= 1.0)) {  // rejected, also when err is NaN (a stage overflowed)
      h *= std::isfinite(err) ? std::max(0.2, 0.9 * std::pow(err, -0.2)) : 0.2;
      rejected = true;
      continue;
    }
    y = next;
    k1 = k7;  // first same as last
    elapsed = last ? dt : elapsed + h;
    const double grow = std::min(rejected ? 1.0 : 5.0, 0.9 * std::pow(std::max(err, 1e-10), -0.2));
    h = std::min(control.largest_step, h * std::max(0.2, grow));
    rejected = false;
  }
  return y;
}

}  // namespace nlobs
