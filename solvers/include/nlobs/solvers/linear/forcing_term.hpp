#pragma once
// Forcing terms η_k of inexact Newton [DES82]: solve J_k s_k = −F_k only to
// ‖F_k + J_k s_k‖ ≤ η_k ‖F_k‖, loosely far from the root and tightly near it, so that the Krylov
// solver does no work the nonlinear iteration throws away (oversolving) and Newton keeps its
// local rate. The choices of Eisenstat and Walker [EW96], as KINSOL offers them
// (KINSetEtaForm: KIN_ETACHOICE1 default, KIN_ETACHOICE2, KIN_ETACONSTANT):
//   choice 1  η_k = |‖F_k‖ − ‖F_{k−1} + J_{k−1} s_{k−1}‖| / ‖F_{k−1}‖,
//             safeguard η_k ← max(η_k, η_{k−1}^φ) when η_{k−1}^φ > 0.1, φ = (1 + √5)/2
//   choice 2  η_k = γ (‖F_k‖ / ‖F_{k−1}‖)^α,
//             safeguard η_k ← max(η_k, γ η_{k−1}^α) when γ η_{k−1}^α > 0.1
//   constant  η_k = η_0
// then η_k ← min(η_k, η_max), and η_k ≥ η_min so that a Krylov solver is never asked for a
// residual below rounding. The first step uses η_0.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "nlobs/common/invalid_input.hpp"

namespace nlobs {

struct ForcingTermOptions {
  enum class Choice { kEisenstatWalker1, kEisenstatWalker2, kConstant };
  Choice choice = Choice::kEisenstatWalker1;
  double initial = 0.1;    // η_0, in (0, 1): the first step's, and choice kConstant's
  double maximum = 0.9;    // η_max, in (0, 1) (KINSOL's default)
  double minimum = 1e-10;  // η_min, in (0, η_max]: floor against asking for rounding noise
  double gamma = 0.9;      // choice 2's γ, in (0, 1]
  double alpha = 2.0;      // choice 2's α, in (1, 2]
};

class ForcingTerm {
 public:
  explicit ForcingTerm(ForcingTermOptions options = {}) : options_(options) {
    auto fail = [](const char* field, double value, const char* requirement) {
      std::ostringstream os;
      os << "ForcingTermOptions::" << field << " = " << value << " " << requirement;
      throw InvalidInput(os.str());
    };
    if (!(options_.initial > 0.0 && options_.initial < 1.0)) {
      fail("initial", options_.initial, "must lie in (0, 1)");
    }
    if (!(options_.maximum > 0.0 && options_.maximum < 1.0)) {
      fail("maximum", options_.maximum, "must lie in (0, 1)");
    }
    if (!(options_.minimum > 0.0 && options_.minimum <= options_.maximum)) {
      fail("minimum", options_.minimum, "must lie in (0, maximum]");
    }
    if (!(options_.gamma > 0.0 && options_.gamma <= 1.0)) {
      fail("gamma", options_.gamma, "must lie in (0, 1]");
    }
    if (!(options_.alpha > 1.0 && options_.alpha <= 2.0)) {
      fail("alpha", options_.alpha, "must lie in (1, 2]");
    }
    restart();
  }

  // A new solve: the next η is η_0.
  void restart() { eta_ = clamp(options_.initial); }
  // η for the current step.
  double eta() const { return eta_; }

  // After a step s_{k−1} was taken: residual_norm = ‖F_k‖, previous_norm = ‖F_{k−1}‖,
  // linear_residual_norm = ‖F_{k−1} + J_{k−1} s_{k−1}‖ (the Krylov solver's final residual;
  // only choice 1 reads it). Sets η_k.
  void update(double residual_norm, double previous_norm, double linear_residual_norm) {
    if (options_.choice == ForcingTermOptions::Choice::kConstant || !(previous_norm > 0.0)) {
      eta_ = clamp(options_.initial);
      return;
    }
    double eta = 0.0, safeguard = 0.0;
    if (options_.choice == ForcingTermOptions::Choice::kEisenstatWalker1) {
      eta = std::abs(residual_norm - linear_residual_norm) / previous_norm;
      safeguard = std::pow(eta_, kGoldenRatio);
    } else {
      eta = options_.gamma * std::pow(residual_norm / previous_norm, options_.alpha);
      safeguard = options_.gamma * std::pow(eta_, options_.alpha);
    }
    if (safeguard > 0.1) eta = std::max(eta, safeguard);
    eta_ = clamp(eta);
  }

  const ForcingTermOptions& options() const { return options_; }

 private:
  static constexpr double kGoldenRatio = 1.6180339887498949;
  double clamp(double eta) const {
    if (!std::isfinite(eta)) return options_.maximum;
    return std::clamp(eta, options_.minimum, options_.maximum);
  }
  ForcingTermOptions options_;
  double eta_ = 0.1;
};

}  // namespace nlobs
