// "window": any engine × a moving-horizon output window (nlobs/observers/window/).
#include <cmath>
#include <optional>
#include <string>

#include "builtin_observer_types.hpp"
#include "covariance_keys.hpp"
#include "nlobs/observers/window/window_estimator.hpp"

namespace nlobs::detail {
namespace {

// Above this a window's samples are refused before anything is allocated.
constexpr long kMaxWindow = 100'000;

struct WindowSpec {
  std::string engine = "newton";
  std::optional<double> tol{};  // step and residual tolerance of the engine
  long window = 0;              // 0 = square
  WarmStart warm_start = WarmStart::kPropagated;
  WindowGain gain = WindowGain::kAuto;
  double gain_scale = 1.0;
  Eigen::MatrixXd measurement_covariance{};  // R; empty: σ² I of a simulated run's noise
  double consistency_quantile = WindowEstimatorOptions{}.consistency_quantile;
};

WindowSpec parse(JsonReader& o, const ModelInstance& model) {
  WindowSpec s;
  s.measurement_covariance = covariance_key(o, "measurement_covariance", model.discrete.outputs());
  s.consistency_quantile =
      o.number("consistency_quantile").value_or(WindowEstimatorOptions{}.consistency_quantile);
  s.engine = o.text("engine").value_or("newton");
  s.tol = o.number("tol");
  s.window = o.integer("window", 0, kMaxWindow).value_or(0);
  const std::string warm = o.text("warm_start").value_or("propagated");
  if (warm != "propagated" && warm != "previous") {
    o.fail("'warm_start' must be propagated or previous");
  }
  s.warm_start = warm == "previous" ? WarmStart::kPrevious : WarmStart::kPropagated;
  if (o.has("psi") && o.json()["psi"].is_number()) {
    s.gain = WindowGain::kScalar;
    s.gain_scale = *o.number("psi");
    if (!std::isfinite(s.gain_scale) || s.gain_scale == 0.0) {
      o.fail("'psi' as a number (Psi = psi I) must be finite and nonzero");
    }
  } else {
    const std::string psi = o.text("psi").value_or("auto");
    if (psi != "auto" && psi != "identity" && psi != "newton") {
      o.fail("'psi' must be auto, identity, newton or a number (got '" + psi + "')");
    }
    s.gain = psi == "identity" ? WindowGain::kIdentity
             : psi == "newton" ? WindowGain::kNewton
                               : WindowGain::kAuto;
  }
  return s;
}

void write(const WindowSpec& s, nlohmann::json& out) {
  out["engine"] = s.engine;
  if (s.tol) out["tol"] = *s.tol;
  out["window"] = s.window;
  out["warm_start"] = s.warm_start == WarmStart::kPrevious ? "previous" : "propagated";
  if (s.measurement_covariance.size()) {
    out["measurement_covariance"] = matrix_json(s.measurement_covariance);
  }
  if (s.consistency_quantile != WindowEstimatorOptions{}.consistency_quantile) {
    out["consistency_quantile"] = s.consistency_quantile;
  }
  switch (s.gain) {
    case WindowGain::kScalar:
      out["psi"] = s.gain_scale;
      break;
    case WindowGain::kIdentity:
      out["psi"] = "identity";
      break;
    case WindowGain::kNewton:
      out["psi"] = "newton";
      break;
    default:
      out["psi"] = "auto";
  }
}

std::unique_ptr<Observer> build(const WindowSpec& s, const ObserverBuild& b) {
  SolverOptions options;
  if (s.tol) {
    options.stop.step_tolerance = *s.tol;
    options.stop.residual_tolerance = *s.tol;
  }
  WindowEstimatorOptions window_options;
  window_options.initial_estimate = b.start;
  window_options.window = s.window;
  window_options.warm_start = s.warm_start;
  window_options.gain = s.gain;
  window_options.gain_scale = s.gain_scale;
  window_options.trace_first_window = b.trace_first_window;
  window_options.consistency_quantile = s.consistency_quantile;
  window_options.measurement_covariance = s.measurement_covariance;
  const double variance = b.output_noise * b.output_noise;
  if (!s.measurement_covariance.size() && variance > 0.0 && std::isfinite(variance)) {
    const Eigen::Index p = b.design.outputs();  // (a square window ignores it)
    window_options.measurement_covariance = variance * Eigen::MatrixXd::Identity(p, p);
  }
  return make_window_estimator(b.model.discrete, s.engine, window_options, options);
}

}  // namespace

void add_window_type(ObserverTypeRegistry& registry) {
  registry.add(observer_type_entry(ObserverTypeDefinition<WindowSpec>{
      .name = "window",
      .description = "any engine x a moving-horizon output window ([MGFF23] for the square one)",
      .condition = "",
      .keys = {{"engine", "engine spec (nlobs list engines)", "newton"},
               {"tol", "the engine's step and residual tolerance", "the engine's"},
               {"window", "samples N of the window; 0: square (N = n)", "0"},
               {"warm_start", "propagated | previous: the next window's first guess", "propagated"},
               {"psi", "auto | identity | newton | a number: the square window's gain", "auto"},
               {"measurement_covariance",
                "R (p x p, or v for v I): the noise a least-squares window's cost is checked "
                "against",
                "noise^2 I of a simulated run without process noise; else none"},
               {"consistency_quantile",
                "in (0, 1): answers with 2V above this quantile of chi2(N p - n) are refused",
                "0.9999"},
               initial_key()},
      .parse = parse,
      .write = write,
      .build = build}));
}

}  // namespace nlobs::detail
