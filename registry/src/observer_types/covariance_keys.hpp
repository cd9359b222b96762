#pragma once
// The covariance keys (Q, R, P0) the Kalman-type observers share: ekf, ukf, mhe.
#include <string>
#include <vector>

#include "builtin_observer_types.hpp"

namespace nlobs::detail {

// The EKF's, the UKF's and the MHE's keys: the three covariances (Q, R, P0), then `extra`, then the
// initial estimate and the design model.
inline std::vector<KeyInfo> kalman_keys(std::vector<KeyInfo> extra) {
  std::vector<KeyInfo> keys = {{"process_covariance", "Q (n x n, or v for v I)", "1e-6 I"},
                               {"measurement_covariance", "R (p x p, or v for v I)", "1e-4 I"},
                               {"initial_covariance", "P0 (n x n, or v for v I)", "I"}};
  keys.insert(keys.end(), extra.begin(), extra.end());
  keys.push_back(initial_key());
  keys.push_back(design_model_key());
  return keys;
}

// A covariance key: a matrix (an array of rows), or one number v for v I of the model's size
// (`size`: n for Q and P0, p for R), so that a model of many states needs no n × n array. The
// options' validate() judges v as it judges the matrix (v < 0 is not positive semi-definite).
inline Eigen::MatrixXd covariance_key(JsonReader& o, const std::string& key, Eigen::Index size) {
  if (o.has(key) && o.json()[key].is_number()) {
    return *o.number(key) * Eigen::MatrixXd::Identity(size, size);
  }
  return o.matrix(key).value_or(Eigen::MatrixXd());
}

// Q, R and P0 from a scenario entry (each optional) into EkfOptions, UkfOptions or MheOptions.
// The scenario has checked x0 against the model's n before its observers are read, so v I is
// no larger than the file that asked for it makes plausible.
template <typename Options>
void read_covariances(JsonReader& o, Options& s, const ModelInstance& model) {
  const Eigen::Index n = model.discrete.states(), p = model.discrete.outputs();
  s.process_covariance = covariance_key(o, "process_covariance", n);
  s.measurement_covariance = covariance_key(o, "measurement_covariance", p);
  s.initial_covariance = covariance_key(o, "initial_covariance", n);
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
