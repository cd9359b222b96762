#pragma once
// High-gain observers in embedded coordinates ([HG-EMB23]) in scenarios:
//   {"type": "high_gain", "N": 6, "theta": 0.1, "map": "ad", "alpha": "explicit", ...}
// built from the scenario's continuous model by name (model_visit.hpp). Keys: docs/cli.md.
#include <Eigen/Core>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "json_reader.hpp"
#include "nlobs/observers/core/observer.hpp"

namespace nlobs::cli {

struct HighGainSpec {
  std::string name;  // default "high_gain"
  int N = 0;         // 0: the model's hand embedding's N
  double theta = 0.1;
  std::vector<double> poles;  // empty: all at −1
  Eigen::VectorXd coefficients;
  // From the model: ad (taylor for N <= 8, else adolc) | taylor (Boost autodiff) | adolc;
  // explicit (hand expansion).
  std::string map = "ad";
  std::string alpha = "auto";  // auto (explicit if the model has one, else lie) | explicit | lie
  bool inverse = false;        // the explicit inverse (oscillator) instead of the projection
  // Saturation: P given, or from a box |x_i| ≤ X_i through the hand map; none when both empty.
  Eigen::MatrixXd saturation_p;
  Eigen::VectorXd saturation_box;
  double saturation_r = 1.0, saturation_rho = 2.0;
  std::string projection = "ceres";
  std::string start = "previous";   // previous | predicted
  std::string integrator = "auto";  // auto | rk4 | cvode
  int substeps = 1;
  double jump_threshold = 0.1, observability_floor = 1e-2, residual_scale = 0.1,
         restart_residual = 1e-2;
  int restart_every = 1;
  std::optional<Eigen::VectorXd> initial_z{};       // ẑ(0)
  std::optional<Eigen::VectorXd> initial_z_from{};  // ẑ(0) = q_N(this x)
};

// The observer object's keys other than "type" and "initial", strictly.
HighGainSpec parse_high_gain_spec(JsonReader& o);
void write_high_gain_spec(const HighGainSpec& spec, nlohmann::json& out);

// Throws InvalidInput (options) or std::invalid_argument (a model the observer cannot take).
std::unique_ptr<Observer> make_high_gain_observer(const HighGainSpec& spec,
                                                  const nlohmann::json& model,
                                                  const Eigen::VectorXd& start, double sample_time,
                                                  const std::string& where);

}  // namespace nlobs::cli
