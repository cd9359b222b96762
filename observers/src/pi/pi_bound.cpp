#include "nlobs/observers/pi/pi_bound.hpp"

#include <algorithm>
#include <complex>
#include <limits>
#include <sstream>

namespace nlobs {
namespace {

using Complex = std::complex<double>;

// Impulse responses of (c1 s + c0) / ((s − r1)(s − r2)) and its L1 norm by the trapezoid rule
// up to e^{−50} of the slowest mode, on grids of at least 2^19 points and 2 000 per oscillation
// period (up to 2^25 for very lightly damped gains). |g| has kinks at sign changes; at that
// density they cost under 1e-6 relative.
struct SecondOrder {
  Complex r1, r2;
  bool repeated = false;
  explicit SecondOrder(const PiGains& g) {
    const Complex disc = std::sqrt(Complex(g.kp * g.kp - 4.0 * g.ki, 0.0));
    r2 = (-g.kp - disc) / 2.0;
    r1 = g.ki / r2;  // r1 r2 = k_i; (−k_p + √disc)/2 cancels when k_p² ≫ k_i
    repeated = std::abs(r1 - r2) <= 1e-7 * std::abs(r1);
  }
  double decay() const { return std::min(-r1.real(), -r2.real()); }
  double frequency() const { return std::abs(r1.imag()); }
  double response(double c1, double c0, double t) const {
    if (repeated) {
      const Complex r = (r1 + r2) / 2.0, e = std::exp(r * t);
      return (c1 * e + (c1 * r + c0) * t * e).real();
    }
    return (((c1 * r1 + c0) * std::exp(r1 * t) - (c1 * r2 + c0) * std::exp(r2 * t)) / (r1 - r2))
        .real();
  }
};

template <typename Integrand>
double trapezoid(Integrand f, double from, double to, double frequency) {
  const double periods = (to - from) * frequency / (2.0 * 3.14159265358979323846);
  const long points = static_cast<long>(
      std::clamp(2000.0 * periods, static_cast<double>(1L << 19), static_cast<double>(1L << 25)));
  const double h = (to - from) / static_cast<double>(points);
  double sum = 0.5 * (f(from) + f(to));
  for (long i = 1; i < points; ++i) sum += f(from + h * static_cast<double>(i));
  return sum * h;
}

// Two grids when the modes are far apart (k_p² ≫ k_i): one that resolves the fast mode until
// it has decayed, one for the slow remainder.
template <typename Integrand>
double integrate_to_decay(const SecondOrder& sys, Integrand f) {
  const double horizon = 50.0 / sys.decay();
  const double fast = std::min(horizon, 50.0 / std::max(-sys.r1.real(), -sys.r2.real()));
  double sum = trapezoid(f, 0.0, fast, sys.frequency());
  if (fast < horizon) sum += trapezoid(f, fast, horizon, sys.frequency());
  return sum;
}

}  // namespace

double pi_l1_gain(const PiGains& gains, double c1, double c0) {
  validate(gains, "pi_l1_gain");
  const SecondOrder sys(gains);
  return integrate_to_decay(sys, [&](double t) { return std::abs(sys.response(c1, c0, t)); });
}

double pi_sinusoid_gain(const PiGains& gains, double omega) {
  validate(gains, "pi_sinusoid_gain");
  return std::abs(Complex(0.0, omega) / Complex(gains.ki - omega * omega, gains.kp * omega));
}

PiBound pi_ultimate_bound(const PiGains& gains, double omega_bound) {
  validate(gains, "pi_ultimate_bound");
  if (!(omega_bound >= 0.0) || !std::isfinite(omega_bound)) {
    std::ostringstream os;
    os << "pi_ultimate_bound: the bound N on |d eta/dt| must be finite and >= 0, got "
       << omega_bound;
    throw InvalidInput(os.str());
  }
  PiBound b;
  b.gains = gains;
  b.omega_bound = omega_bound;
  const double kp = gains.kp, ki = gains.ki, disc = kp * kp - 4.0 * ki;
  if (disc >= 0.0) {
    // Eigenvalues of K: roots of λ² − k_p λ + k_i, both real and > 0 here.
    const double lmax = (kp + std::sqrt(disc)) / 2.0, lmin = ki / lmax;
    b.paper_delta = std::sqrt(lmax / lmin) * 2.0 * omega_bound * std::sqrt(lmax) / lmin;
  } else {
    b.paper_delta = std::numeric_limits<double>::quiet_NaN();
    std::ostringstream os;
    os << "K of eq. (7) has complex eigenvalues for k_p = " << kp << ", k_i = " << ki
       << " (k_p^2 < 4 k_i): the theorem's condition lambda_min(K) > 0 fails and the paper's "
          "delta (eq. 15) is undefined; the error still converges to a ball (s^2 + k_p s + k_i "
          "is stable) whose size eta_error and error_norm give";
    b.warnings.push_back(os.str());
  }
  if (omega_bound == 0.0) return b;  // both bounds are 0: no quadrature (callers after warnings)
  const SecondOrder sys(gains);
  b.eta_error = omega_bound * pi_l1_gain(gains, 1.0, 0.0);
  b.error_norm = omega_bound * integrate_to_decay(sys, [&](double t) {
                   return std::hypot(sys.response(1.0, 0.0, t), sys.response(0.0, 1.0, t));
                 });
  return b;
}

}  // namespace nlobs
