#pragma once
// An implicit step for stiff plants, generic in the scalar: the three-stage, third-order,
// L-stable, stiffly accurate SDIRK method of [Ale77] (as [HW96] §IV.6 gives it),
//   Y_i = x + h Σ_{j≤i} a_ij F(Y_j, t + c_i h),   x⁺ = Y_3,
//   γ = 0.4358665215…, the root of 6γ³ − 18γ² + 9γ − 1 = 0 in (1/6, 1/2);
//   c = (γ, (1 + γ)/2, 1);  a_21 = (1 − γ)/2;  a_31 = −(6γ² − 16γ + 1)/4,
//   a_32 = (6γ² − 20γ + 5)/4, a_33 = γ.
// Each stage is solved on doubles by a simplified Newton iteration with the step's one matrix
// M = I − hγ ∂F/∂x(x) (one LU per step: the diagonal is the same for every stage), to an
// increment of 1 % of the tolerance atol + rtol |Y| ([HW96] §IV.8; with a rounding floor). On AD
// scalars the stage values are kept and their derivative is the implicit function theorem's,
//   (I − hγ J(Y_i)) dY_i = dx + h Σ_{j<i} a_ij J(Y_j) dY_j,
// applied as one Newton correction on those scalars with J at the converged Y_i, so the EKF,
// the MHE and the windows get the exact Jacobian of this discrete map (not of the exact flow),
// and the value is the double one bit for bit.
// A stage whose iteration fails (rate ≥ 0.9, 10 iterations, not finite) splits the step in
// halves, at most ten times (2^-10 h); then IntegrationFailure names why, t and the state. A
// state, or F at it, that is not finite is passed on not finite (the caller's to judge).
// Dense: an n × n LU per step on doubles; on AD scalars also a Jacobian, an LU and an inverse
// per stage, and the double solve again for every ⌈n / 8⌉ directions of a run-time size: the
// AD Jacobian of one move costs O(n⁴ / 8). The scheme is refused above
// DiscretizationOptions::kMostImplicitStates.
#include <Eigen/Core>
#include <Eigen/LU>
#include <array>
#include <cmath>
#include <sstream>
#include <type_traits>

#include "nlobs/models/integration_failure.hpp"
#include "nlobs/models/model.hpp"
#include "nlobs/models/scalar_value.hpp"
#include "nlobs/models/vector_field_jacobian.hpp"

namespace nlobs {

struct ImplicitStepControl {
  static constexpr int kMostHalvings = 10;
  double absolute_tolerance = 1e-8;
  double relative_tolerance = 1e-6;
};

namespace detail {

struct Sdirk3Tableau {
  static constexpr double gamma = 0.43586652150845899941601945119356;
  static constexpr double c2 = (1.0 + gamma) / 2;
  static constexpr double a21 = (1.0 - gamma) / 2;
  static constexpr double a31 = -(6.0 * gamma * gamma - 16.0 * gamma + 1.0) / 4;
  static constexpr double a32 = (6.0 * gamma * gamma - 20.0 * gamma + 5.0) / 4;
};

// The double stages of one step of length h from x0 (where F is f0, finite): null, or why an
// iteration failed.
template <ContinuousModel Model>
const char* sdirk3_stages(const Model& model, const ModelVector<double, Model::kStates>& x0,
                          const ModelVector<double, Model::kStates>& f0,
                          const ModelVector<double, Model::kInputs>& u, double t, double h,
                          const ImplicitStepControl& control,
                          std::array<ModelVector<double, Model::kStates>, 3>& stages,
                          std::array<ModelVector<double, Model::kStates>, 3>& slopes) {
  using State = ModelVector<double, Model::kStates>;
  using Square = Eigen::Matrix<double, Model::kStates, Model::kStates>;
  using Tableau = Sdirk3Tableau;
  const Eigen::Index n = x0.size();
  const double hg = h * Tableau::gamma;
  Square jacobian;
  vector_field_jacobian(model, x0, u, t, jacobian);
  if (!jacobian.allFinite()) return "∂F/∂x is not finite at the step's start";
  const Eigen::PartialPivLU<Square> lu(Square(Square::Identity(n, n) - hg * jacobian));
  const std::array<double, 3> c{Tableau::gamma, Tableau::c2, 1.0};
  for (int i = 0; i < 3; ++i) {
    State base = x0;
    if (i == 1) base += h * Tableau::a21 * slopes[0];
    if (i == 2) base += h * (Tableau::a31 * slopes[0] + Tableau::a32 * slopes[1]);
    State y = base + hg * (i == 0 ? f0 : slopes[i - 1]);
    double previous = 0.0;
    bool converged = false;
    for (int iteration = 0; iteration < 10 && !converged; ++iteration) {
      const State residual = y - base - hg * model.vector_field(y, u, t + c[i] * h);
      const State increment = lu.solve(residual);
      y -= increment;
      // 1e-12 ‖Y‖∞ is the rounding floor: an increment at rounding level counts as converged
      // whatever the tolerances.
      const double floor = 1e-12 * y.array().abs().maxCoeff();
      const double norm =
          std::sqrt((increment.array() / (control.absolute_tolerance + floor +
                                          control.relative_tolerance * y.array().abs()))
                        .square()
                        .sum() /
                    static_cast<double>(std::max<Eigen::Index>(n, 1)));
      if (!std::isfinite(norm)) return "Newton's iteration left the finite numbers";
      converged = norm <= 1e-2;
      if (!converged && iteration > 0 && norm >= 0.9 * previous) {
        return "Newton's iteration stalled (contraction rate >= 0.9): the stage equation may "
               "have no solution near here";
      }
      previous = norm;
    }
    if (!converged) return "Newton's iteration did not converge in 10 iterations";
    stages[i] = y;
    slopes[i] = model.vector_field(y, u, t + c[i] * h);
    if (!slopes[i].allFinite()) return "F is not finite at a converged stage";
  }
  return nullptr;
}

}  // namespace detail

// One step of length h from x(t); splits itself on a stalled iteration (`halvings` so far).
template <ContinuousModel Model, typename T>
ModelVector<T, Model::kStates> sdirk3_step(const Model& model,
                                           const ModelVector<T, Model::kStates>& x,
                                           const ModelVector<double, Model::kInputs>& u, double t,
                                           double h, const ImplicitStepControl& control,
                                           int halvings = 0) {
  using State = ModelVector<T, Model::kStates>;
  using Values = ModelVector<double, Model::kStates>;
  using Square = Eigen::Matrix<double, Model::kStates, Model::kStates>;
  using Tableau = detail::Sdirk3Tableau;
  const Eigen::Index n = x.size();
  Values x0(n);
  for (Eigen::Index i = 0; i < n; ++i) x0[i] = scalar_value(x[i]);
  if (!x0.allFinite()) return x;  // not finite: the caller's to judge
  const Values f0 = model.vector_field(x0, u, t);
  if (!f0.allFinite()) {  // as after an explicit step: not finite, the caller's to judge
    return State(x + h * model.vector_field(x, u, t));
  }
  std::array<Values, 3> stages, slopes;
  if (const char* why = detail::sdirk3_stages(model, x0, f0, u, t, h, control, stages, slopes)) {
    if (halvings == ImplicitStepControl::kMostHalvings) {
      std::ostringstream os;
      os << "sdirk3: " << why << ", on a step of " << h << " (h / 2^" << halvings
         << ") at t = " << t << " from x = [" << x0.transpose()
         << "]: the state has likely left the model's range (or the plant needs more substeps)";
      throw IntegrationFailure(os.str());
    }
    const State half = sdirk3_step(model, x, u, t, h / 2, control, halvings + 1);
    return sdirk3_step(model, half, u, t + h / 2, h / 2, control, halvings + 1);
  }
  if constexpr (std::is_same_v<T, double>) {
    return stages[2];
  } else {
    // Y_i = Y_i* − (C − value(C)), C = M_i⁻¹ G(Y_i*, x, Y_<i), M_i = I − hγ J(Y_i*): the value
    // stays Y_i* exactly (C − value(C) has value 0), the derivative is the implicit function
    // theorem's.
    const std::array<double, 3> c{Tableau::gamma, Tableau::c2, 1.0};
    const double hg = h * Tableau::gamma;
    std::array<State, 3> slope;
    State stage(n);
    Square jacobian;
    for (int i = 0; i < 3; ++i) {
      vector_field_jacobian(model, stages[i], u, t + c[i] * h, jacobian);
      const Square inverse =
          Eigen::PartialPivLU<Square>(Square(Square::Identity(n, n) - hg * jacobian)).inverse();
      State g(n);
      for (Eigen::Index r = 0; r < n; ++r) {
        g[r] = T(stages[i][r] - hg * slopes[i][r]) - x[r];
        if (i == 1) g[r] -= (h * Tableau::a21) * slope[0][r];
        if (i == 2) {
          g[r] -= (h * Tableau::a31) * slope[0][r];
          g[r] -= (h * Tableau::a32) * slope[1][r];
        }
      }
      for (Eigen::Index r = 0; r < n; ++r) {
        T correction(0.0);
        for (Eigen::Index k = 0; k < n; ++k) correction += inverse(r, k) * g[k];
        stage[r] = T(stages[i][r]) - (correction - T(scalar_value(correction)));
      }
      if (i < 2) slope[i] = model.vector_field(stage, u, t + c[i] * h);
    }
    return stage;
  }
}

}  // namespace nlobs
