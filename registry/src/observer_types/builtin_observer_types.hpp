#pragma once
// The built-in observer types, each registered in its own file as a user's type would be.
#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <vector>

#include "nlobs/registry/observer_types.hpp"

namespace nlobs::detail {

void add_window_type(ObserverTypeRegistry& registry);
void add_baseline_types(ObserverTypeRegistry& registry);  // luenberger, sliding_mode, ekf, ukf
void add_mhe_type(ObserverTypeRegistry& registry);
void add_pi_bank_type(ObserverTypeRegistry& registry);
void add_mvt_type(ObserverTypeRegistry& registry);
void add_high_gain_type(ObserverTypeRegistry& registry);
void add_modulating_type(ObserverTypeRegistry& registry);
void add_finite_difference_type(ObserverTypeRegistry& registry);

// In the order `nlobs list observers` prints them.
inline void add_builtin_observer_types(ObserverTypeRegistry& registry) {
  add_window_type(registry);
  add_baseline_types(registry);
  add_mhe_type(registry);
  add_pi_bank_type(registry);
  add_mvt_type(registry);
  add_high_gain_type(registry);
  add_modulating_type(registry);
  add_finite_difference_type(registry);
}

inline std::vector<double> std_vector(const Eigen::VectorXd& v) {
  return std::vector<double>(v.data(), v.data() + v.size());
}
inline nlohmann::json matrix_json(const Eigen::MatrixXd& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index i = 0; i < m.rows(); ++i) rows.push_back(std_vector(m.row(i).transpose()));
  return rows;
}

// The keys every type that takes them shares.
inline KeyInfo initial_key() {
  return {"initial", "start estimate x(0) (n numbers)", "the scenario's initial_guess"};
}
inline KeyInfo design_model_key() {
  return {"model", "the observer's own design model (a model spec, the scenario model's sizes)",
          "the scenario's model"};
}

}  // namespace nlobs::detail
