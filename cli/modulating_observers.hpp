#pragma once
// Modulating-function observers ([MF-LTV]) in scenarios:
//   {"type": "modulating", "horizon": 1.0, "degree": 5, "sample_period": 0.1, ...}
// built from the scenario's model by name: the catalogue models with a canonical form
// (modulating_forms.hpp: lti-injection, pendulum). Keys: docs/cli.md.
#include <Eigen/Core>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "json_reader.hpp"
#include "nlobs/observers/core/observer.hpp"

namespace nlobs::cli {

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

// The observer object's keys other than "type" and "initial", strictly.
ModulatingSpec parse_modulating_spec(JsonReader& o);
void write_modulating_spec(const ModulatingSpec& spec, nlohmann::json& out);

// Throws InvalidInput (options) or std::invalid_argument (a model without a canonical form).
std::unique_ptr<Observer> make_modulating_observer(const ModulatingSpec& spec,
                                                   const nlohmann::json& model,
                                                   const Eigen::VectorXd& start, double sample_time,
                                                   const std::string& where);

}  // namespace nlobs::cli
