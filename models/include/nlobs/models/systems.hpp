#pragma once
// The dynamic systems of [BMH], [FFMG19], [MF-LTV], [HG-EMB23], each with its documented
// parameters. Every function is generic in the scalar (AD). Inputs, where a system has them, are
// plain doubles.
#include <cmath>
#include <functional>
#include <sstream>
#include <string>

#include "nlobs/models/model.hpp"

namespace nlobs {

// Cubic Chua circuit ([FFMG19], example 4), y = x2:
//   x1' = a (x2 − x1 − m0 x1 − m1 x1³),  x2' = x1 − x2 + x3,  x3' = −b x2.
struct CubicChuaParameters {
  double a = 9.5, b = 100.0 / 7.0, m0 = -8.0 / 7.0, m1 = 4.0 / 63.0;
};
struct CubicChua : ModelSizes<3, 0, 1> {
  CubicChuaParameters p{};
  template <typename T>
  State<T> vector_field(const State<T>& x, const Input&, double) const {
    State<T> dx;
    dx[0] = p.a * (x[1] - x[0] - p.m0 * x[0] - p.m1 * x[0] * x[0] * x[0]);
    dx[1] = x[0] - x[1] + x[2];
    dx[2] = -p.b * x[1];
    return dx;
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return Output<T>(x[1]);
  }
};

// Lorenz system ([HG-EMB23]), (σ, ρ, β) = (10, 28, 8/3), y = x1.
struct LorenzParameters {
  double sigma = 10.0, rho = 28.0, beta = 8.0 / 3.0;
};
struct Lorenz : ModelSizes<3, 0, 1> {
  LorenzParameters p{};
  template <typename T>
  State<T> vector_field(const State<T>& x, const Input&, double) const {
    State<T> dx;
    dx[0] = p.sigma * (x[1] - x[0]);
    dx[1] = x[0] * (p.rho - x[2]) - x[1];
    dx[2] = x[0] * x[1] - p.beta * x[2];
    return dx;
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return Output<T>(x[0]);
  }
};

// Duffing oscillator ([HG-EMB23]): x1' = x2, x2' = x1 − x1³, y = x2.
struct Duffing : ModelSizes<2, 0, 1> {
  template <typename T>
  State<T> vector_field(const State<T>& x, const Input&, double) const {
    return State<T>(x[1], x[0] - x[0] * x[0] * x[0]);
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return Output<T>(x[1]);
  }
};

// Van der Pol oscillator ([HG-EMB23]): x1' = x2, x2' = −x1 − μ x2 (x1² − 1), y = x2; μ = 1
// gives the form −x1 − x2(x1² − 1), the standard oscillator with a stable limit cycle.
struct VanDerPol : ModelSizes<2, 0, 1> {
  double mu = 1.0;
  template <typename T>
  State<T> vector_field(const State<T>& x, const Input&, double) const {
    return State<T>(x[1], -x[0] - mu * x[1] * (x[0] * x[0] - 1.0));
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return Output<T>(x[1]);
  }
};

// Harmonic oscillator with a nonlinear output ([HG-EMB23]): x1' = x2, x2' = −x1,
// y = x1² + x1.
struct OscillatorNonlinearOutput : ModelSizes<2, 0, 1> {
  template <typename T>
  State<T> vector_field(const State<T>& x, const Input&, double) const {
    return State<T>(x[1], -x[0]);
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return Output<T>(x[0] * x[0] + x[0]);
  }
};

// Chaotic system without linear term ([BMH], example 1), y = (x1, x2):
//   x' = [ln(0.1 + exp(x2 − x1)), x1 x3, 0.2 − x1 x2].
struct ChaoticNoLinear : ModelSizes<3, 0, 2> {
  template <typename T>
  State<T> vector_field(const State<T>& x, const Input&, double) const {
    using std::exp;
    using std::log;
    State<T> dx;
    dx[0] = log(0.1 + exp(x[1] - x[0]));
    dx[1] = x[0] * x[2];
    dx[2] = 0.2 - x[0] * x[1];
    return dx;
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return x.template head<2>();
  }
};

// Flexible-joint robot ([BMH], example 2): x' = A x + B u + φ(x), y = (x1, x2, x3),
// A rows [0 1 0 0], [−48.6 −1.25 48.6 0], [0 0 0 1], [19.5 0 −19.5 0], B = [0 21.6 0 0]ᵀ,
// φ = [0 0 0 −3.33 sin x3]ᵀ.
struct FlexibleJointRobotParameters {
  double k1 = 48.6, damping = 1.25, k2 = 19.5, gain = 21.6, gravity = 3.33;
};
struct FlexibleJointRobot : ModelSizes<4, 1, 3> {
  FlexibleJointRobotParameters p{};
  template <typename T>
  State<T> vector_field(const State<T>& x, const Input& u, double) const {
    using std::sin;
    State<T> dx;
    dx[0] = x[1];
    dx[1] = -p.k1 * x[0] - p.damping * x[1] + p.k1 * x[2] + p.gain * u[0];
    dx[2] = x[3];
    dx[3] = p.k2 * x[0] - p.k2 * x[2] - p.gravity * sin(x[2]);
    return dx;
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return x.template head<3>();
  }
};

// Lunar lander ([FFMG19], example 5): x1' = x2, x2' = g − σαu/x3, x3' = −σu − f(t),
// y = x1; g = 1.63, σ = 50, α = 200, f(t) = exp(6 sin t) the unknown mass loss. Domain: the
// mass x3 stays > 0 (it reaches zero in finite time).
struct LunarLanderParameters {
  double g = 1.63, sigma = 50.0, alpha = 200.0;
  std::function<double(double)> disturbance = [](double t) { return std::exp(6.0 * std::sin(t)); };
};
struct LunarLander : ModelSizes<3, 1, 1> {
  LunarLanderParameters p{};
  template <typename T>
  State<T> vector_field(const State<T>& x, const Input& u, double t) const {
    State<T> dx;
    dx[0] = x[1];
    dx[1] = p.g - p.sigma * p.alpha * u[0] / x[2];
    dx[2] = T(-p.sigma * u[0] - p.disturbance(t));
    return dx;
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return Output<T>(x[0]);
  }
  std::string domain_violation(const State<double>& x) const {
    if (x[2] > 0.0) return {};
    std::ostringstream os;
    os << "lunar lander: mass x3 = " << x[2] << " is not > 0: the model leaves its domain";
    return os.str();
  }
};

// The lander with its unknown mass-loss term f immersed as a fourth state, so that a run has
// f's true values ([FFMG19], eq. 52): f = exp(c sin t) gives f' = c cos t · f, f(0) = 1.
// c = 0 makes f constant: the design model of an observer that only knows f varies slowly.
struct LunarLanderImmersed : ModelSizes<4, 1, 1> {
  LunarLanderParameters p{};
  double c = 6.0;
  template <typename T>
  State<T> vector_field(const State<T>& x, const Input& u, double t) const {
    State<T> dx;
    dx[0] = x[1];
    dx[1] = p.g - p.sigma * p.alpha * u[0] / x[2];
    dx[2] = -p.sigma * u[0] - x[3];
    dx[3] = c * std::cos(t) * x[3];
    return dx;
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return Output<T>(x[0]);
  }
  std::string domain_violation(const State<double>& x) const {
    return LunarLander{}.domain_violation(x.head<3>());
  }
};

// Example 3 of [FFMG19] without its x1 (x1' = u never reaches y = x2): x' = u + f, y = x,
// with the unknown f = A sin(ωt) immersed as a second state (f' = Aω cos ωt, f(0) = 0).
// A = 0 makes f constant: the design model of an observer that does not know f's shape.
struct UnknownInputIntegrator : ModelSizes<2, 1, 1> {
  double amplitude = 3.0, omega = 3.14159265358979323846;
  template <typename T>
  State<T> vector_field(const State<T>& x, const Input& u, double t) const {
    return State<T>(u[0] + x[1], T(amplitude * omega * std::cos(omega * t)));
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return Output<T>(x[0]);
  }
};

// Second-order LTI system with a nonlinear output injection ([MF-LTV], the modulating-function
// paper's first example; its parameters were lost, these are the issue's):
//   x1' = x2,  x2' = −a0 x1 − a1 x2 + gain · sin(y),  y = x1.
struct LtiInjectionParameters {
  double a0 = 1.0, a1 = 0.5, gain = 1.0;
};
struct LtiOutputInjection : ModelSizes<2, 0, 1> {
  LtiInjectionParameters p{};
  template <typename T>
  State<T> vector_field(const State<T>& x, const Input&, double) const {
    using std::sin;
    return State<T>(x[1], -p.a0 * x[0] - p.a1 * x[1] + p.gain * sin(x[0]));
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return Output<T>(x[0]);
  }
};

// Pendulum with time-varying friction and an unknown bounded horizontal acceleration
// ([MF-LTV]; the paper's table was lost, these values are ours): θ = x1, y = θ,
//   x1' = x2,  x2' = −(g/l) sin x1 − c(t) x2 − (a(t)/l) cos x1,
//   c(t) = c0 + c1 sin(ωc t),  a(t) = a_max sin(ωa t).
struct PendulumParameters {
  double g = 9.81, length = 1.0, c0 = 0.5, c1 = 0.2, omega_c = 1.0, a_max = 0.0, omega_a = 2.0;
};
struct PendulumTimeVaryingFriction : ModelSizes<2, 0, 1> {
  PendulumParameters p{};
  double friction(double t) const { return p.c0 + p.c1 * std::sin(p.omega_c * t); }
  double acceleration(double t) const { return p.a_max * std::sin(p.omega_a * t); }
  template <typename T>
  State<T> vector_field(const State<T>& x, const Input&, double t) const {
    using std::cos;
    using std::sin;
    return State<T>(x[1], -(p.g / p.length) * sin(x[0]) - friction(t) * x[1] -
                              (acceleration(t) / p.length) * cos(x[0]));
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return Output<T>(x[0]);
  }
};

// The gas-phase batch reactor of the moving-horizon estimation literature ([HR05]; [RM09],
// Example 4.27), concentrations x = (c_A, c_B, c_C), y = RT (c_A + c_B + c_C), the total pressure:
//   A ⇌ B + C (k1, k2),  2B ⇌ C (k3, k4),  r1 = k1 c_A − k2 c_B c_C,  r2 = k3 c_B² − k4 c_C,
//   c_A' = −r1,  c_B' = r1 − 2 r2,  c_C' = r1 + r2.
// Defined for every c (an estimator may try negative concentrations; the physics needs c ≥ 0).
struct BatchReactorParameters {
  double k1 = 0.5, k2 = 0.05, k3 = 0.2, k4 = 0.01, rt = 32.84;
};
struct BatchReactor : ModelSizes<3, 0, 1> {
  BatchReactorParameters p{};
  template <typename T>
  State<T> vector_field(const State<T>& x, const Input&, double) const {
    const T r1 = p.k1 * x[0] - p.k2 * x[1] * x[2];
    const T r2 = p.k3 * x[1] * x[1] - p.k4 * x[2];
    return State<T>(-r1, r1 - 2.0 * r2, r1 + r2);
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return Output<T>(p.rt * (x[0] + x[1] + x[2]));
  }
};

}  // namespace nlobs
