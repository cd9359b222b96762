#pragma once
// Gain guidance for the PI observer ([FFMG19] eqs. 7–16): how large the estimation
// error stays, ultimately, for gains (k_p, k_i) when |Ω| = |η̇| ≤ N (hypothesis H2).
//
// The error E = (e1, e2), e1 = η − η̂, e2' = e1, obeys eq. (7): E' = −K E + (Ω, 0)ᵀ with
// K = [[k_p, k_i], [−1, 0]]. Two bounds are reported:
//
// * the paper's δ of eq. (15), √(λmax/λmin) · 2N√λmax / λmin. Its proof (eq. 12) applies the
//   Rayleigh inequality to K, which is not symmetric: sym(K) has a zero diagonal entry and is
//   indefinite for every gain, so δ is not proven. We evaluate it with the eigenvalues of K
//   when they are real (k_p² ≥ 4 k_i) and report NaN plus a warning when they are complex.
// * ours, from the variation-of-constants formula E(t) = e^{−Kt}E(0) + ∫ e^{−K(t−τ)} e₁ Ω(τ) dτ:
//   limsup |e1| ≤ N ∫₀^∞ |g1|,  limsup ‖E‖ ≤ N ∫₀^∞ ‖(g1, g2)‖₂, where g2 is the impulse response
//   of 1/(s² + k_p s + k_i) and g1 = g2'. For |e1| this is the smallest bound valid for every Ω
//   with |Ω| ≤ N (a bang-bang Ω attains it), and it holds for every k_p, k_i > 0.
#include <string>
#include <vector>

#include "nlobs/observers/pi/pi_observer.hpp"

namespace nlobs {

struct PiBound {
  PiGains gains{};
  double omega_bound = 0.0;  // N
  double paper_delta = 0.0;  // eq. (15); NaN when K has complex eigenvalues
  double eta_error = 0.0;    // ultimate bound on |η − η̂|
  double error_norm = 0.0;   // ultimate bound on ‖E‖₂ (what δ claims to bound)
  std::vector<std::string> warnings;
};

// Throws InvalidInput for gains that are not finite and > 0, or N not finite and >= 0.
PiBound pi_ultimate_bound(const PiGains& gains, double omega_bound);

// ∫₀^∞ |g(t)| dt for g the impulse response of (c1 s + c0) / (s² + k_p s + k_i): the L∞ → L∞
// gain of that filter. (c1, c0) = (1, 0) is e1 per unit Ω; (1, k_p) is e1 + k_p e2, the error
// of a state reconstructed by integrating η̂₁ (docs/observers.md, pi-chua).
double pi_l1_gain(const PiGains& gains, double c1, double c0);

// Steady-state amplitude of e1 per unit amplitude of a sinusoidal Ω of angular frequency ω:
// |jω / (k_i − ω² + j k_p ω)|.
double pi_sinusoid_gain(const PiGains& gains, double omega);

}  // namespace nlobs
