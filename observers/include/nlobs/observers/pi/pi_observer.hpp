#pragma once
// The model-free PI reduced-order observer of [FFMG19] for one auxiliary quantity
//   η = a ṡ + b(u, y),   a constant, s a signal we have (an output, or an earlier estimate).
//
// The observer of eq. (3),  η̂' = k_p (η − η̂) + η̂₁,  η̂₁' = k_i (η − η̂),  needs ṡ. Lemma 1
// (eq. 18) removes it with γ1 = η̂ − k_p a s, γ2 = η̂₁ − k_i a s:
//   γ1' = −k_p γ1 + γ2 + k_p (b − k_p a s) + k_i a s
//   γ2' = −k_i γ1 + k_i (b − k_p a s)
//   η̂ = γ1 + k_p a s,   η̂₁ = γ2 + k_i a s     (η̂₁ tends to η̇: the "rate" estimate)
// Both forms are here: the γ form is what runs; the direct form is the reference the tests
// compare it with on a signal whose derivative is known.
#include <Eigen/Core>
#include <cmath>
#include <sstream>
#include <string>

#include "nlobs/solvers/status.hpp"

namespace nlobs {

struct PiGains {
  double kp = 0.0;  // proportional gain k_p > 0
  double ki = 0.0;  // integral gain k_i > 0
};

// Both gains finite and > 0: with them −K of eq. (7) is Hurwitz (its characteristic
// polynomial is s² + k_p s + k_i). Throws InvalidInput naming `where` and the gain otherwise.
inline void validate(const PiGains& g, const std::string& where) {
  const auto check = [&](double v, const char* name) {
    if (!(v > 0.0) || !std::isfinite(v)) {
      std::ostringstream os;
      os << where << ": gain " << name << " = " << v
         << " must be finite and > 0 (the error dynamics s^2 + k_p s + k_i must be stable)";
      throw InvalidInput(os.str());
    }
  };
  check(g.kp, "k_p");
  check(g.ki, "k_i");
}

// One channel's constants: η = a ṡ + b.
struct PiChannelConstants {
  PiGains gains{};
  double a = 1.0;
};

// d/dt (γ1, γ2) of eq. (18), given s and b at the same instant.
inline Eigen::Vector2d pi_gamma_rate(const PiChannelConstants& c, const Eigen::Vector2d& gamma,
                                     double s, double b) {
  const double kp = c.gains.kp, ki = c.gains.ki;
  const double shifted = b - kp * c.a * s;  // b − k_p a s
  return {-kp * gamma[0] + gamma[1] + kp * shifted + ki * c.a * s, -ki * gamma[0] + ki * shifted};
}

// (η̂, η̂₁) from (γ1, γ2) and s.
inline Eigen::Vector2d pi_estimates(const PiChannelConstants& c, const Eigen::Vector2d& gamma,
                                    double s) {
  return {gamma[0] + c.gains.kp * c.a * s, gamma[1] + c.gains.ki * c.a * s};
}

// (γ1, γ2) that give the estimates (η̂, η̂₁) at s: the inverse of pi_estimates.
inline Eigen::Vector2d pi_gamma_for(const PiChannelConstants& c, const Eigen::Vector2d& estimates,
                                    double s) {
  return {estimates[0] - c.gains.kp * c.a * s, estimates[1] - c.gains.ki * c.a * s};
}

// d/dt (η̂, η̂₁) of eq. (3) when η itself is known (the direct form).
inline Eigen::Vector2d pi_direct_rate(const PiGains& g, const Eigen::Vector2d& estimates,
                                      double eta) {
  const double e = eta - estimates[0];
  return {g.kp * e + estimates[1], g.ki * e};
}

}  // namespace nlobs
