#pragma once
// MVT observers ([BMH]) in scenarios: {"type": "mvt", "error_guess": [...], ...}. The
// observer needs the continuous model with AD, so it is built from the scenario's model by name
// (model_visit.hpp), one MvtObserver<Model> per catalogue model.
#include <Eigen/Core>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "json_reader.hpp"
#include "nlobs/observers/core/observer.hpp"

namespace nlobs::cli {

struct MvtSpec {
  std::string name;             // default "mvt:" + variant
  Eigen::VectorXd error_guess;  // ê(0)
  double eta = 1.0;
  std::string variant = "injection";  // injection | published
  double injection_gain = 10.0;       // γ of the injection variant
  std::string beta_solver = "per-row";
  std::string integrator = "rk4";  // rk4 | dopri5
  int substeps = 1;
};

// The observer object's keys other than "type" and "initial" (which the caller reads), strictly.
MvtSpec parse_mvt_spec(JsonReader& o);
void write_mvt_spec(const MvtSpec& spec, nlohmann::json& out);

// Throws InvalidInput (bad options, an output that is not [I_m 0] x) or std::invalid_argument.
std::unique_ptr<Observer> make_mvt_observer(const MvtSpec& spec, const nlohmann::json& model,
                                            const Eigen::VectorXd& start, double sample_time,
                                            const std::string& where);

}  // namespace nlobs::cli
