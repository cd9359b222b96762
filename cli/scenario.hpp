#pragma once
// Scenarios for `nlobs run`: built-in ones by name, or JSON files with the same fields
// (docs/cli.md). Parsing is strict: an unknown key, a wrong type or a missing field is an
// error naming the file and the key.
#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "high_gain_observers.hpp"
#include "modulating_observers.hpp"
#include "mvt_observers.hpp"
#include "nlobs/observers/core/any_model.hpp"
#include "nlobs/observers/core/observer.hpp"
#include "pi_banks.hpp"

namespace nlobs::cli {

// Limits checked before anything is allocated: samples of a run (n × steps doubles per
// observer are kept), samples of a window.
inline constexpr long kMaxSteps = 10'000'000;
inline constexpr long kMaxWindow = 100'000;

struct ObserverSpec {
  // "window", "luenberger", "sliding_mode", "ekf", "pi_bank", "mvt", "high_gain", "modulating",
  // "finite_difference"
  std::string type;
  // window
  std::string engine = "newton";
  std::optional<double> tol{};  // step and residual tolerance of the engine
  long window = 0;              // 0 = square
  std::string warm_start = "propagated";
  // Ψ of a square window: "auto", "identity", "newton", or "scalar" with psi_scale (the JSON
  // key "psi" holds the word or the number)
  std::string psi = "auto";
  double psi_scale = 1.0;
  // luenberger: gain (n×p); sliding_mode: Q, R (n×p), gamma
  Eigen::MatrixXd gain, q, r;
  double gamma = 1.0;
  // ekf
  Eigen::MatrixXd process_covariance, measurement_covariance, initial_covariance;
  std::optional<Eigen::VectorXd> initial{};  // start estimate; default: the scenario's guess
  // luenberger, sliding_mode, ekf: the observer's own design model (same sizes and sample
  // time as the scenario's), e.g. one that assumes an unknown input constant
  std::optional<nlohmann::json> model{};
  PiBankSpec pi{};              // pi_bank
  MvtSpec mvt{};                // mvt
  HighGainSpec high_gain{};     // high_gain
  ModulatingSpec modulating{};  // modulating
  std::string label;            // finite_difference: its name
};

struct InputSpec {
  std::string kind = "zero";                // zero | constant | sin
  double value = 0.0;                       // constant
  double amplitude = 1.0, frequency = 1.0;  // sin: amplitude · sin(frequency · t)
};

// Figures a paper reported, printed beside ours: observer name → {"mse": x,
// "first_window_iterations": n}.
using ReportedFigures = std::map<std::string, std::map<std::string, double>>;

struct Scenario {
  std::string name;
  nlohmann::json model;  // {"name": ..., "parameters": {...}, "scheme": ..., "step": ...}
  Eigen::VectorXd x0, initial_guess;
  long steps = 400;
  double noise = 0.0;
  std::uint64_t seed = 1;
  InputSpec input;
  std::vector<ObserverSpec> observers;
  ReportedFigures reported;
  // Start of "after": metrics after the transient (MSE, max error) count t >= settle_time;
  // negative: after the longest window has filled.
  double settle_time = -1.0;
};

std::vector<std::string> builtin_scenarios();
// A built-in name, or a path to a JSON file. Throws std::invalid_argument otherwise.
Scenario load_scenario(const std::string& name_or_file);
Scenario parse_scenario(const nlohmann::json& json, const std::string& where);
nlohmann::json to_json(const Scenario& scenario);

// Builds the model and the observers a scenario describes. `trace_first_window`: window
// estimators record the engine's trace of their first window (for the convergence plot).
AnyModel scenario_model(const Scenario& scenario);
std::vector<std::unique_ptr<Observer>> make_observers(const Scenario& scenario,
                                                      const AnyModel& model,
                                                      bool trace_first_window);
Eigen::VectorXd scenario_input(const Scenario& scenario, const AnyModel& model, long k);

// Per PI channel of the scenario's pi_bank observers: the gains, N, the paper's δ (eq. 15) and
// our ultimate bounds (pi_bound.hpp); warnings (complex eigenvalues of K) are appended.
nlohmann::json pi_bounds_json(const Scenario& scenario, std::vector<std::string>* warnings);

}  // namespace nlobs::cli
