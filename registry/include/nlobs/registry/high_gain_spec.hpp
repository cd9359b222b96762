#pragma once
// What a scenario's high_gain observer asks for ([HG-EMB23]; keys: docs/cli.md): the
// observer's options and the choices of its design (which observability map, which α), read
// from the observer's JSON object and handed to the model's high-gain hook (register_model.hpp),
// which knows the model's own type.
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

namespace nlobs {

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

}  // namespace nlobs
