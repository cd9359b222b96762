#pragma once
// What a scenario's modulating observer asks for ([MF-LTV]; keys: docs/cli.md), handed to the
// model's modulating hook (register_model.hpp), which builds the observer on the model's
// canonical form.
#include <Eigen/Core>
#include <string>

namespace nlobs {

struct ModulatingSpec {
  std::string name;  // default "modulating"
  double horizon = 1.0;
  int order = 0, degree = 0;      // 0: n, and the minimal degree order + n − 1
  Eigen::VectorXd noise_weights;  // empty: the form's a_i at t = 0
  std::string engine = "ceres";
  std::string quadrature = "simpson";  // simpson | trapezoid
  double sample_period = 0.0;          // 0: every sample (FIR mode)
  bool resample = false;
  double resample_max_gap = 0.0;   // 0: 4 steps
  bool disturbance_bound = false;  // Theorem 1's bound from the model's disturbance level
};

}  // namespace nlobs
