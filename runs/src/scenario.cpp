#include "nlobs/runs/scenario.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

#include "nlobs/common/printable.hpp"
#include "nlobs/registry/json_reader.hpp"
#include "nlobs/runs/input_file.hpp"

namespace nlobs {
namespace {

nlohmann::json vector_json(const Eigen::VectorXd& v) {
  return std::vector<double>(v.data(), v.data() + v.size());
}

// The paper's experiment ([MGFF23]). The paper omits the true state, the run length and
// the noise: x0 = [1, 2.1428, -0.1648] reproduces its first-window fixed point; 400 samples
// (20 s at T = 0.05); noise-free by default (--noise adds it).
const char* kChuaFp = R"({
  "name": "chua-fp",
  "model": {"name": "modified-chua", "scheme": "euler", "step": 0.05},
  "x0": [1.0, 2.1428, -0.1648],
  "initial_guess": [5.0, 10.0, -5.0],
  "steps": 400,
  "noise": 0.0,
  "seed": 1,
  "observers": [
    {"type": "window", "engine": "picard", "tol": 1e-5},
    {"type": "window", "engine": "aitken", "tol": 1e-5},
    {"type": "window", "engine": "steffensen", "tol": 1e-5},
    {"type": "window", "engine": "anderson", "tol": 1e-5},
    {"type": "window", "engine": "newton", "tol": 1e-5},
    {"type": "window", "engine": "ceres", "tol": 1e-8, "window": 6},
    {"type": "luenberger", "gain": [0.5, 0.4, 0.2]},
    {"type": "sliding_mode", "Q": [0.1, 0.2, 0.1], "R": [4.1, 2.1, 3.9], "gamma": 10},
    {"type": "ekf", "process_covariance": [[1e-6, 0, 0], [0, 1e-6, 0], [0, 0, 1e-6]],
     "measurement_covariance": [[1e-4]], "initial_covariance": [[10, 0, 0], [0, 10, 0], [0, 0, 10]]}
  ],
  "reported": {
    "window:picard": {"mse": 0.0165, "first_window_iterations": 284},
    "window:aitken": {"mse": 0.0165, "first_window_iterations": 139},
    "window:steffensen": {"mse": 0.0165, "first_window_iterations": 42},
    "window:newton": {"mse": 0.0180, "first_window_iterations": 3},
    "luenberger": {"mse": 0.3335},
    "sliding_mode": {"mse": 0.3025}
  }
})";

// [FFMG19], example 3: f = 3 sin(πt) immersed as state x2, u = 2 sin(πt),
// gains (8, 15), γ(0) = 0. N = max|f'| = 3π. 10 s at the model's step 1 ms; after t = 2 s.
// The EKF's own model assumes f constant (amplitude 0): it must track f through Q.
const char* kPiLinear = R"({
  "name": "pi-linear",
  "model": {"name": "unknown-input", "scheme": "rk4", "step": 0.001},
  "x0": [0.0, 0.0],
  "initial_guess": [0.0, 0.0],
  "steps": 10001,
  "settle_time": 2.0,
  "input": {"kind": "sin", "amplitude": 2.0, "frequency": 3.141592653589793},
  "observers": [
    {"type": "pi_bank", "bank": "unknown-input", "gains": [[8, 15]],
     "omega_bounds": {"f": 9.42477796076938}},
    {"type": "ekf", "model": {"name": "unknown-input", "parameters": {"amplitude": 0}, "step": 0.001},
     "process_covariance": [[1e-10, 0], [0, 1e-4]], "measurement_covariance": [[1e-6]],
     "initial_covariance": [[1, 0], [0, 100]]}
  ]
})";

// [FFMG19], example 4: the cubic Chua circuit, y = x2, x0 = (0.2, 0.2, 0.2), gains (25, 150),
// γ(0) = 0, x̂1(0) = 0. N = 3.5 bounds |d(x1 + x3)/dt| on this run (measured max 3.20, see
// docs/observers.md). 50 s at 1 ms; after t = 10 s. chua-x3 is our alternative reconstruction.
const char* kPiChua = R"({
  "name": "pi-chua",
  "model": {"name": "cubic-chua", "scheme": "rk4", "step": 0.001},
  "x0": [0.2, 0.2, 0.2],
  "initial_guess": [0.0, 0.0, 0.0],
  "steps": 50001,
  "settle_time": 10.0,
  "observers": [
    {"type": "pi_bank", "bank": "chua", "gains": [[25, 150]], "omega_bounds": {"eta": 3.5}},
    {"type": "pi_bank", "bank": "chua-x3", "gains": [[25, 150]], "omega_bounds": {"eta": 3.5}},
    {"type": "ekf", "process_covariance": [[1e-8, 0, 0], [0, 1e-8, 0], [0, 0, 1e-8]],
     "measurement_covariance": [[1e-6]], "initial_covariance": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}
  ]
})";

// [FFMG19], example 5: the lunar lander with f = exp(6 sin t) immersed as x4, u = 1,
// x0 = (−700, 0, 1500), gains (6, 25) for x2 and (49, 700) for f, γ(0) = 0. Asked for 15 s at
// 1 ms; the mass reaches zero near t = 13.05 s and the run stops there with the domain message.
// N for f: max|d/dt exp(6 sin t)| = 588.2; x2' = g − σα/x3 is unbounded as x3 → 0, so no N.
// The EKF's model assumes f constant (c = 0).
const char* kPiLander = R"({
  "name": "pi-lander",
  "model": {"name": "lander-f", "scheme": "rk4", "step": 0.001},
  "x0": [-700.0, 0.0, 1500.0, 1.0],
  "initial_guess": [-700.0, 0.0, 1200.0, 0.0],
  "steps": 15001,
  "settle_time": 5.0,
  "input": {"kind": "constant", "value": 1.0},
  "observers": [
    {"type": "pi_bank", "bank": "lander", "gains": [[6, 25], [49, 700]],
     "omega_bounds": {"f": 588.2}},
    {"type": "ekf", "model": {"name": "lander-f", "parameters": {"c": 0}, "step": 0.001},
     "process_covariance": [[1e-10, 0, 0, 0], [0, 1e-8, 0, 0], [0, 0, 1e-4, 0], [0, 0, 0, 0.5]],
     "measurement_covariance": [[1e-6]],
     "initial_covariance": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1e5, 0], [0, 0, 0, 100]]}
  ]
})";

// [BMH], example 1: the chaotic system without linear term, y = (x1, x2),
// x0 = (−2, −1, −1), x̂0 = (−1, −0.5, −1.5), η = 1, 30 s at 1 ms (plant RK4, observer RK4 at the
// sample step, y between samples by the cubic through the last four samples). Case 1:
// ê0 = x0 − x̂0; case 2: ê0's third entry 0.2 instead of 0.5. The published structure and our
// output-injection correction (γ = 10) side by side, and an EKF on the same data.
const char* kMvtChaotic = R"({
  "name": "mvt-chaotic",
  "model": {"name": "chaotic", "scheme": "rk4", "step": 0.001},
  "x0": [-2.0, -1.0, -1.0],
  "initial_guess": [-1.0, -0.5, -1.5],
  "steps": 30001,
  "settle_time": 20.0,
  "observers": [
    {"type": "mvt", "name": "mvt-case1", "variant": "published", "error_guess": [-1.0, -0.5, 0.5]},
    {"type": "mvt", "name": "mvt-case1-injection", "variant": "injection",
     "error_guess": [-1.0, -0.5, 0.5]},
    {"type": "mvt", "name": "mvt-case2", "variant": "published", "error_guess": [-1.0, -0.5, 0.2]},
    {"type": "mvt", "name": "mvt-case2-injection", "variant": "injection",
     "error_guess": [-1.0, -0.5, 0.2]},
    {"type": "ekf", "process_covariance": [[1e-10, 0, 0], [0, 1e-10, 0], [0, 0, 1e-10]],
     "measurement_covariance": [[1e-6, 0], [0, 1e-6]],
     "initial_covariance": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}
  ]
})";

// [BMH], example 2: the flexible-joint robot, u = sin t, y = (x1, x2, x3), x0 = (3, 3, 3, 3),
// x̂0 = (−1, −2, −0.5, −1), η = 1, 15 s at 1 ms. The paper's ê0 = x0 − x̂0, and one that misses
// x4 by 1 (published and corrected).
const char* kMvtRobot = R"({
  "name": "mvt-robot",
  "model": {"name": "robot", "scheme": "rk4", "step": 0.001},
  "x0": [3.0, 3.0, 3.0, 3.0],
  "initial_guess": [-1.0, -2.0, -0.5, -1.0],
  "steps": 15001,
  "settle_time": 5.0,
  "input": {"kind": "sin", "amplitude": 1.0, "frequency": 1.0},
  "observers": [
    {"type": "mvt", "name": "mvt", "variant": "published", "error_guess": [4.0, 5.0, 3.5, 4.0]},
    {"type": "mvt", "name": "mvt-other-e0", "variant": "published",
     "error_guess": [4.0, 5.0, 3.5, 3.0]},
    {"type": "mvt", "name": "mvt-other-e0-injection", "variant": "injection",
     "error_guess": [4.0, 5.0, 3.5, 3.0]},
    {"type": "ekf", "process_covariance": [[1e-10, 0, 0, 0], [0, 1e-10, 0, 0], [0, 0, 1e-10, 0],
                                           [0, 0, 0, 1e-10]],
     "measurement_covariance": [[1e-6, 0, 0], [0, 1e-6, 0], [0, 0, 1e-6]],
     "initial_covariance": [[10, 0, 0, 0], [0, 10, 0, 0], [0, 0, 10, 0], [0, 0, 0, 10]]}
  ]
})";

// [HG-EMB23]: the Duffing oscillator's hard start ẑ(0) = q6(0, 0) while x(0) is on an
// orbit around the equilibrium (1, 0); P, R, ρ and θ are the paper's. The hand q6 (the maps from
// the model give the same run, "map": "ad" 7× and "adolc" 100× slower).
constexpr const char* kHgDuffing = R"({
  "name": "hg-duffing",
  "model": {"name": "duffing", "scheme": "rk4", "step": 0.001},
  "x0": [1.2, 0.0],
  "initial_guess": [0.0, 0.0],
  "steps": 20001,
  "settle_time": 15.0,
  "observers": [
    {"type": "high_gain", "name": "hg-duffing", "N": 6, "theta": 0.1, "alpha": "explicit",
     "map": "explicit",
     "saturation": {"P_diagonal": [0.8, 0.145, 0.103, 0.0158, 4.07e-3, 5.26e-4], "R": 1.0,
                    "rho": 2.0},
     "initial_z_from": [0.0, 0.0]},
    {"type": "ekf", "process_covariance": [[1e-10, 0], [0, 1e-10]],
     "measurement_covariance": [[1e-6]], "initial_covariance": [[1, 0], [0, 1]]}
  ]
})";

// The oscillator with y = x1² + x1: x(0) = (−1/2, 0), initial error (0.2, 0), θ = 0.3, the
// paper's P; the explicit inverse (the paper) beside the least-squares projection (through the
// hand q4: the maps from the model give the same run at 2.5× (Taylor) and 80× (ADOL-C) the cost).
constexpr const char* kHgOscillator = R"({
  "name": "hg-oscillator",
  "model": {"name": "oscillator", "scheme": "rk4", "step": 0.001},
  "x0": [-0.5, 0.0],
  "initial_guess": [-0.3, 0.0],
  "steps": 40001,
  "settle_time": 30.0,
  "observers": [
    {"type": "high_gain", "name": "hg-inverse", "N": 4, "theta": 0.3, "alpha": "explicit",
     "inverse": true,
     "saturation": {"P_diagonal": [0.594, 0.421, 0.266, 0.153], "R": 1.0, "rho": 2.0}},
    {"type": "high_gain", "name": "hg-projection", "N": 4, "theta": 0.3, "alpha": "explicit",
     "map": "explicit",
     "saturation": {"P_diagonal": [0.594, 0.421, 0.266, 0.153], "R": 1.0, "rho": 2.0}},
    {"type": "ekf", "process_covariance": [[1e-10, 0], [0, 1e-10]],
     "measurement_covariance": [[1e-6]], "initial_covariance": [[1, 0], [0, 1]]}
  ]
})";

// Lorenz, y = x1, N = 4: α = L_f^4 h along the prediction (α(z) is rational, singular on the
// x3 axis); P from the box |x| ≤ (25, 30, 55) around the attractor ([HG-EMB23] §6).
constexpr const char* kHgLorenz = R"({
  "name": "hg-lorenz",
  "model": {"name": "lorenz", "scheme": "rk4", "step": 0.001},
  "x0": [1.0, 1.0, 20.0],
  "initial_guess": [2.0, 3.0, 25.0],
  "steps": 10001,
  "settle_time": 5.0,
  "observers": [
    {"type": "high_gain", "name": "hg-lorenz", "N": 4, "theta": 0.02, "alpha": "lie",
     "saturation": {"box": [25.0, 30.0, 55.0], "R": 1.0, "rho": 2.0}},
    {"type": "ekf", "process_covariance": [[1e-10, 0, 0], [0, 1e-10, 0], [0, 0, 1e-10]],
     "measurement_covariance": [[1e-6]],
     "initial_covariance": [[10, 0, 0], [0, 10, 0], [0, 0, 10]]}
  ]
})";

// Van der Pol, y = x2, N = 5: α = L_f^5 h along the prediction; high gain (θ = 0.02), as the
// paper found; P from the box |x| ≤ (2.5, 3) around the limit cycle.
constexpr const char* kHgVdp = R"({
  "name": "hg-vdp",
  "model": {"name": "van-der-pol", "scheme": "rk4", "step": 0.001},
  "x0": [2.0, 0.0],
  "initial_guess": [1.0, 1.0],
  "steps": 20001,
  "settle_time": 15.0,
  "observers": [
    {"type": "high_gain", "name": "hg-vdp", "N": 5, "theta": 0.02, "alpha": "lie",
     "saturation": {"box": [2.5, 3.0], "R": 1.0, "rho": 2.0}},
    {"type": "ekf", "process_covariance": [[1e-10, 0], [0, 1e-10]],
     "measurement_covariance": [[1e-6]], "initial_covariance": [[1, 0], [0, 1]]}
  ]
})";

// [MF-LTV]: y'' + 0.5 y' + y = sin y sampled every 10 ms with noise σ = 0.01. The
// modulating-function observer (T = 1 s) on every sample and in sampled-data mode (outputs every
// 0.1 s, the predictor between), beside backward differences and a least-squares window
// estimator (20 samples) on the same data.
constexpr const char* kMfLti = R"({
  "name": "mf-lti",
  "model": {"name": "lti-injection", "scheme": "rk4", "step": 0.01},
  "x0": [2.0, 0.0],
  "initial_guess": [0.0, 0.0],
  "steps": 2001,
  "noise": 0.01,
  "settle_time": 2.0,
  "observers": [
    {"type": "modulating", "name": "mf", "horizon": 1.0},
    {"type": "modulating", "name": "mf-sampled", "horizon": 1.0, "sample_period": 0.1},
    {"type": "finite_difference", "name": "finite-difference"},
    {"type": "window", "engine": "ceres", "window": 20}
  ]
})";

// The pendulum with friction c(t) = 0.5 + 0.2 sin t and an unknown horizontal acceleration
// a(t) = 0.5 sin 2t (|d| ≤ 0.5): the observer treats d as a disturbance; Theorem 1's bound
// beside its error (`--sweep a_max=…` re-simulates per level, the paper's Fig. 9).
constexpr const char* kMfPendulum = R"({
  "name": "mf-pendulum",
  "model": {"name": "pendulum", "parameters": {"a_max": 0.5}, "scheme": "rk4", "step": 0.01},
  "x0": [1.0, 0.0],
  "initial_guess": [0.0, 0.0],
  "steps": 2001,
  "settle_time": 2.0,
  "observers": [
    {"type": "modulating", "name": "mf", "horizon": 1.0, "disturbance_bound": true},
    {"type": "modulating", "name": "mf-sampled", "horizon": 1.0, "sample_period": 0.05},
    {"type": "finite_difference", "name": "finite-difference"}
  ]
})";

// The batch reactor of the MHE literature ([HR05]; [RM09], Example 4.27; do-mpc, MPCTools and
// HILO-MPC ship it): a poor prior x̂0 = (1, 0, 4) for x0 = (0.5, 0.05, 0), σ_v = 0.25 on the
// pressure, σ_w = 0.001 on every concentration, σ_p = 0.5 on the prior, N = 10, 30 s at
// Δ = 0.25. The EKF, the UKF and the MHE with and without c ≥ 0 share the noise statistics.
const char* kMheBatchReactor = R"({
  "name": "mhe-batch-reactor",
  "model": {"name": "batch-reactor", "scheme": "rk4", "step": 0.25},
  "x0": [0.5, 0.05, 0.0],
  "initial_guess": [1.0, 0.0, 4.0],
  "steps": 121,
  "noise": 0.25,
  "process_noise": 0.001,
  "seed": 1,
  "settle_time": 5.0,
  "observers": [
    {"type": "ekf", "process_covariance": [[1e-6, 0, 0], [0, 1e-6, 0], [0, 0, 1e-6]],
     "measurement_covariance": [[0.0625]],
     "initial_covariance": [[0.25, 0, 0], [0, 0.25, 0], [0, 0, 0.25]]},
    {"type": "ukf", "process_covariance": [[1e-6, 0, 0], [0, 1e-6, 0], [0, 0, 1e-6]],
     "measurement_covariance": [[0.0625]],
     "initial_covariance": [[0.25, 0, 0], [0, 0.25, 0], [0, 0, 0.25]]},
    {"type": "mhe", "name": "mhe", "horizon": 10,
     "process_covariance": [[1e-6, 0, 0], [0, 1e-6, 0], [0, 0, 1e-6]],
     "measurement_covariance": [[0.0625]],
     "initial_covariance": [[0.25, 0, 0], [0, 0.25, 0], [0, 0, 0.25]]},
    {"type": "mhe", "name": "mhe-bounded", "horizon": 10, "lower_bounds": [0, 0, 0],
     "process_covariance": [[1e-6, 0, 0], [0, 1e-6, 0], [0, 0, 1e-6]],
     "measurement_covariance": [[0.0625]],
     "initial_covariance": [[0.25, 0, 0], [0, 0.25, 0], [0, 0, 0.25]]}
  ]
})";

const std::map<std::string, const char*>& builtin_texts() {
  static const std::map<std::string, const char*> texts = {{"chua-fp", kChuaFp},
                                                           {"pi-linear", kPiLinear},
                                                           {"pi-chua", kPiChua},
                                                           {"pi-lander", kPiLander},
                                                           {"mvt-chaotic", kMvtChaotic},
                                                           {"mvt-robot", kMvtRobot},
                                                           {"hg-duffing", kHgDuffing},
                                                           {"hg-oscillator", kHgOscillator},
                                                           {"hg-lorenz", kHgLorenz},
                                                           {"hg-vdp", kHgVdp},
                                                           {"mf-lti", kMfLti},
                                                           {"mf-pendulum", kMfPendulum},
                                                           {"mhe-batch-reactor", kMheBatchReactor}};
  return texts;
}

}  // namespace

std::vector<std::string> builtin_scenarios() {
  std::vector<std::string> names;
  for (const auto& [name, text] : builtin_texts()) names.push_back(name);
  return names;
}

Scenario load_scenario(const std::string& name_or_file) {
  if (auto it = builtin_texts().find(name_or_file); it != builtin_texts().end()) {
    return parse_scenario(nlohmann::json::parse(it->second), "built-in scenario " + it->first);
  }
  std::error_code ec;
  if (!std::filesystem::exists(name_or_file, ec) && !ec) {  // an error: open_input_file says it
    std::string list;
    for (const auto& s : builtin_scenarios()) list += (list.empty() ? "" : ", ") + s;
    throw std::invalid_argument("'" + name_or_file + "' is neither a built-in scenario (" + list +
                                ") nor a JSON file");
  }
  std::ifstream in = open_input_file(name_or_file, "scenario file");
  return parse_scenario(parse_json(in, name_or_file), name_or_file);
}

Scenario parse_scenario(const nlohmann::json& json, const std::string& where) {
  JsonReader r(json, where);
  Scenario s;
  s.name = r.required_text("name");
  if (!r.has("model")) r.fail("missing field 'model'");
  auto model_spec = r.object("model");
  s.model = model_spec->json();
  // Built now, to validate (naming keys), and kept for the run.
  auto built = std::make_shared<const Scenario::BuiltModel>(
      Scenario::BuiltModel{s.model, make_model_instance(*model_spec)});
  const ModelInstance& instance = built->instance;
  const AnyModel& model = instance.discrete;
  s.x0 = r.required_vector("x0");
  s.initial_guess = r.required_vector("initial_guess");
  // Sizes against the model before the observers are read: a covariance given as one number v
  // becomes v I of the model's size there, which x0's n entries make no larger than the file.
  if (s.x0.size() != model.states() || s.initial_guess.size() != model.states()) {
    r.fail("'x0' and 'initial_guess' must have " + std::to_string(model.states()) +
           " entries (the model's states)");
  }
  if (auto v = r.integer("steps", 1, kMaxScenarioSteps)) s.steps = *v;
  if (auto v = r.number("noise")) {
    if (*v < 0) r.fail("'noise' must be >= 0");
    s.noise = *v;
  }
  if (auto v = r.number("process_noise")) {
    if (*v < 0) r.fail("'process_noise' must be >= 0");
    s.process_noise = *v;
  }
  if (auto v = r.integer("seed", 0, std::numeric_limits<long>::max())) {
    s.seed = static_cast<std::uint64_t>(*v);
  }
  if (auto v = r.number("settle_time")) {
    if (!(*v >= 0.0) || !std::isfinite(*v)) r.fail("'settle_time' must be finite and >= 0 (s)");
    s.settle_time = *v;
  }
  if (auto in = r.object("input")) {
    s.input.kind = in->text("kind").value_or("zero");
    if (s.input.kind != "zero" && s.input.kind != "constant" && s.input.kind != "sin") {
      in->fail("'kind' must be zero, constant or sin");
    }
    s.input.value = in->number("value").value_or(0.0);
    s.input.amplitude = in->number("amplitude").value_or(1.0);
    s.input.frequency = in->number("frequency").value_or(1.0);
    in->finish({"kind", "value", "amplitude", "frequency"});
  }
  for (JsonReader& o : r.objects("observers")) {
    s.observers.push_back(parse_observer_spec(o, instance));
  }
  if (s.observers.empty()) r.fail("'observers' must list at least one observer");
  if (auto rep = r.object("reported")) {
    const nlohmann::json& raw = rep->json();
    for (auto it = raw.begin(); it != raw.end(); ++it) {
      auto entry = rep->object(it.key());
      for (const char* key : {"mse", "first_window_iterations"}) {
        if (auto v = entry->number(key)) s.reported[it.key()][key] = *v;
      }
      entry->finish({"mse", "first_window_iterations"});
    }
  }
  r.finish({"name", "model", "x0", "initial_guess", "steps", "noise", "process_noise", "seed",
            "input", "observers", "reported", "settle_time"});
  s.built_model = std::move(built);
  return s;
}

nlohmann::json to_json(const Scenario& s) {
  nlohmann::json j;
  j["name"] = s.name;
  j["model"] = s.model;
  j["x0"] = vector_json(s.x0);
  j["initial_guess"] = vector_json(s.initial_guess);
  j["steps"] = s.steps;
  j["noise"] = s.noise;
  if (s.process_noise > 0.0) j["process_noise"] = s.process_noise;
  j["seed"] = s.seed;
  j["input"] = {{"kind", s.input.kind},
                {"value", s.input.value},
                {"amplitude", s.input.amplitude},
                {"frequency", s.input.frequency}};
  nlohmann::json observers = nlohmann::json::array();
  for (const ObserverSpec& o : s.observers) observers.push_back(observer_spec_json(o));
  j["observers"] = observers;
  if (!s.reported.empty()) j["reported"] = s.reported;
  if (s.settle_time >= 0.0) j["settle_time"] = s.settle_time;
  return j;
}

ModelInstance scenario_model(const Scenario& s) {
  // The model parse_scenario built, unless the scenario's model has been edited since (a sweep
  // over one of its parameters).
  if (s.built_model && s.built_model->spec == s.model) return s.built_model->instance;
  JsonReader m(s.model, s.name + ".model");
  return make_model_instance(m);
}

Measurements simulate_scenario(const Scenario& s, const AnyModel& model) {
  SimulationOptions sim;
  sim.steps = s.steps;
  sim.noise_std = s.noise;
  sim.process_noise_std = s.process_noise;
  sim.seed = s.seed;
  sim.sample_time = model.sample_time() > 0 ? model.sample_time() : 1.0;
  sim.input = [&s, &model](long k) { return scenario_input(s, model, k); };
  return simulate(model, s.x0, sim);
}

Eigen::VectorXd scenario_input(const Scenario& s, const AnyModel& model, long k) {
  Eigen::VectorXd u = Eigen::VectorXd::Zero(model.inputs());
  if (u.size() == 0 || s.input.kind == "zero") return u;
  // Inputs are held over a sample.
  const double t = static_cast<double>(k) * model.sample_time();
  u.setConstant(s.input.kind == "constant" ? s.input.value
                                           : s.input.amplitude * std::sin(s.input.frequency * t));
  return u;
}

std::vector<std::unique_ptr<Observer>> make_observers(const Scenario& s,
                                                      const ModelInstance& instance,
                                                      bool trace_first_window) {
  std::vector<std::unique_ptr<Observer>> out;
  for (size_t i = 0; i < s.observers.size(); ++i) {
    const ObserverSpec& o = s.observers[i];
    out.push_back(build_observer(o, instance, o.initial.value_or(s.initial_guess),
                                 s.name + ".observers[" + std::to_string(i) + "]",
                                 trace_first_window));
  }
  return out;
}

nlohmann::json observer_reports(const Scenario& s, std::vector<std::string>* warnings) {
  nlohmann::json out = nlohmann::json::array();
  for (size_t i = 0; i < s.observers.size(); ++i) {
    const ObserverSpec& o = s.observers[i];
    const ObserverTypeEntry& entry = observer_type_registry().get(o.type);
    if (!entry.report) continue;
    nlohmann::json items;
    try {  // a user's report hook: anything it throws is named
      items = entry.report(o.spec, warnings);
    } catch (...) {
      throw std::invalid_argument(s.name + ".observers[" + std::to_string(i) +
                                  "]: observer type '" + o.type +
                                  "': its report threw: " + current_exception_text());
    }
    for (auto& item : items) out.push_back(std::move(item));
  }
  return out;
}

}  // namespace nlobs
