#pragma once
// The options of the MVT observer ([BMH]) and of its β solver, apart from the observer so that
// code that only builds or checks options (a scenario reader, MvtOptions::validate()) does not
// compile the observer, Ceres and NLopt. mvt_observer.hpp and mvt_beta.hpp say what each
// field does to the method.
#include <Eigen/Core>
#include <string>
#include <string_view>

#include "nlobs/common/invalid_input.hpp"

namespace nlobs {

enum class MvtBetaMethod { kPerRow, kNlopt, kCeres };

inline std::string_view to_string(MvtBetaMethod m) {
  switch (m) {
    case MvtBetaMethod::kPerRow:
      return "per-row";
    case MvtBetaMethod::kNlopt:
      return "nlopt";
    case MvtBetaMethod::kCeres:
      return "ceres";
  }
  return "unknown";
}

// "per-row", "nlopt" or "ceres"; anything else is InvalidInput listing them.
inline MvtBetaMethod mvt_beta_method_from_string(std::string_view name) {
  for (MvtBetaMethod m : {MvtBetaMethod::kPerRow, MvtBetaMethod::kNlopt, MvtBetaMethod::kCeres}) {
    if (to_string(m) == name) return m;
  }
  throw InvalidInput("MvtBetaOptions::method = '" + std::string(name) +
                     "' is not a beta solver; valid: per-row, nlopt, ceres");
}

struct MvtBetaOptions {
  // Default chosen by measurement (docs/observers.md, bench BM_MvtStep): per-row is fastest at
  // equal accuracy on both of the paper's examples.
  MvtBetaMethod method = MvtBetaMethod::kPerRow;
  // Target |X_i(β_i)| (absolute). A row whose residual cannot get below the rounding floor
  // 8ε(|F_i(x̂)| + |F_i(x̂ + ê)|) stops there.
  double tolerance = 1e-12;
  int max_iterations = 60;                   // per row (per-row) or per solve (nlopt, ceres)
  std::string nlopt_algorithm = "LD_SLSQP";  // a gradient-based NLopt algorithm with bounds
  // nlopt, ceres: rows the joint solve left above their tolerance get the per-row search. A
  // minimiser of ½‖X‖² can stop at a bound where X_i ≠ 0 but ∂(X_i²)/∂β_i points outward (the
  // robot shows it, docs/observers.md); off, the engine's answer is returned as it is.
  bool polish_rows = true;
};

enum class MvtVariant { kPublished, kOutputInjection };
enum class MvtIntegrator { kRk4, kDopri5 };

struct MvtOptions {
  std::string name = "mvt";          // in reports
  Eigen::VectorXd initial_estimate;  // x̂(0): n finite numbers (required)
  // ê(0), the guess of the error x(0) − x̂(0): n finite numbers; empty: 0. ê tracks e exactly
  // only from ê(0) = x(0) − x̂(0) (the paper's case 1); the output-injection variant recovers
  // from any other.
  Eigen::VectorXd initial_error_estimate{};
  double sample_time = 0.0;  // seconds between samples k and k + 1 (> 0)
  double eta = 1.0;          // η ≥ 1 in Ḡ = η diag(α)
  MvtVariant variant = MvtVariant::kOutputInjection;
  // γ ≥ 0 in K_b = J_ba + γ J_abᵀ Ḡ_a (kOutputInjection); 10 measured on both paper examples
  double injection_gain = 10.0;
  MvtBetaOptions beta{};
  MvtIntegrator integrator = MvtIntegrator::kRk4;
  int substeps = 1;                   // RK4 steps per sample interval
  double absolute_tolerance = 1e-10;  // kDopri5
  double relative_tolerance = 1e-10;  // kDopri5
  // Throws InvalidInput naming the field and its value: an empty name, an initial estimate
  // not given or not finite, an error estimate not finite, T, tolerances not finite and > 0,
  // η < 1, γ < 0, substeps < 1.
  void validate() const;
};

}  // namespace nlobs
