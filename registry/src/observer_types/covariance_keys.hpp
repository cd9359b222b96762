#pragma once
// The covariance keys (Q, R, P0) the Kalman-type observers share: ekf, ukf, mhe.
#include <vector>

#include "builtin_observer_types.hpp"

namespace nlobs::detail {

// The EKF's, the UKF's and the MHE's keys: the three covariances (Q, R, P0), then `extra`, then the
// initial estimate and the design model.
inline std::vector<KeyInfo> kalman_keys(std::vector<KeyInfo> extra) {
  std::vector<KeyInfo> keys = {{"process_covariance", "Q (n x n)", "1e-6 I"},
                               {"measurement_covariance", "R (p x p)", "1e-4 I"},
                               {"initial_covariance", "P0 (n x n)", "I"}};
  keys.insert(keys.end(), extra.begin(), extra.end());
  keys.push_back(initial_key());
  keys.push_back(design_model_key());
  return keys;
}

// Q, R and P0 from a scenario entry (each optional) into EkfOptions, UkfOptions or MheOptions.
template <typename Options>
void read_covariances(JsonReader& o, Options& s) {
  s.process_covariance = o.matrix("process_covariance").value_or(Eigen::MatrixXd());
  s.measurement_covariance = o.matrix("measurement_covariance").value_or(Eigen::MatrixXd());
  s.initial_covariance = o.matrix("initial_covariance").value_or(Eigen::MatrixXd());
}

// The covariances that were given, back to JSON.
template <typename Options>
void write_covariances(const Options& s, nlohmann::json& out) {
  if (s.process_covariance.size()) out["process_covariance"] = matrix_json(s.process_covariance);
  if (s.measurement_covariance.size()) {
    out["measurement_covariance"] = matrix_json(s.measurement_covariance);
  }
  if (s.initial_covariance.size()) out["initial_covariance"] = matrix_json(s.initial_covariance);
}

}  // namespace nlobs::detail
