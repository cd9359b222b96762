// The classic baselines on the discretised model (AD Jacobians through AnyModel): luenberger,
// sliding_mode, ekf, and the backward differences finite_difference. Their specs are the
// library's own options; the start estimate is filled when built.
#include <vector>

#include "builtin_observer_types.hpp"
#include "covariance_keys.hpp"
#include "nlobs/observers/baselines/baselines.hpp"
#include "nlobs/observers/baselines/finite_difference_observer.hpp"
#include "nlobs/observers/baselines/unscented_kalman_filter.hpp"

namespace nlobs::detail {
namespace {

Eigen::MatrixXd required_matrix(JsonReader& o, const std::string& key) {
  Eigen::MatrixXd m = o.matrix(key).value_or(Eigen::MatrixXd());
  if (m.size() == 0) o.fail("missing field '" + key + "'");
  return m;
}

void add_luenberger(ObserverTypeRegistry& registry) {
  registry.add(observer_type_entry(ObserverTypeDefinition<LuenbergerOptions>{
      .name = "luenberger",
      .description = "constant-gain observer x+ = f(x, u) + L (y - h(x))",
      .condition = "",
      .keys = {{"gain", "L (n x p; a flat array is a column)", ""},
               initial_key(),
               design_model_key()},
      .parse =
          [](JsonReader& o, const ModelInstance&) {
            LuenbergerOptions s;
            s.gain = required_matrix(o, "gain");
            return s;
          },
      .write = [](const LuenbergerOptions& s,
                  nlohmann::json& out) { out["gain"] = matrix_json(s.gain); },
      .build = [](LuenbergerOptions s, const ObserverBuild& b) -> std::unique_ptr<Observer> {
        s.initial_estimate = b.start;
        return std::make_unique<LuenbergerObserver<AnyModel>>(b.design, std::move(s));
      }}));
}

void add_sliding_mode(ObserverTypeRegistry& registry) {
  registry.add(observer_type_entry(ObserverTypeDefinition<SlidingModeOptions>{
      .name = "sliding_mode",
      .description = "sliding-mode observer with a saturated switching term",
      .condition = "",
      .keys = {{"Q", "linear gain (n x p)", ""},
               {"R", "switching gain (n x p)", ""},
               {"gamma", "boundary layer of sat(e / gamma), > 0", "1"},
               initial_key(),
               design_model_key()},
      .parse =
          [](JsonReader& o, const ModelInstance&) {
            SlidingModeOptions s;
            s.q = o.matrix("Q").value_or(Eigen::MatrixXd());
            s.r = o.matrix("R").value_or(Eigen::MatrixXd());
            if (s.q.size() == 0 || s.r.size() == 0) o.fail("missing field 'Q' or 'R'");
            s.gamma = o.number("gamma").value_or(s.gamma);  // SlidingModeOptions' default
            return s;
          },
      .write =
          [](const SlidingModeOptions& s, nlohmann::json& out) {
            out["Q"] = matrix_json(s.q);
            out["R"] = matrix_json(s.r);
            out["gamma"] = s.gamma;
          },
      .build = [](SlidingModeOptions s, const ObserverBuild& b) -> std::unique_ptr<Observer> {
        s.initial_estimate = b.start;
        return std::make_unique<SlidingModeObserver<AnyModel>>(b.design, std::move(s));
      }}));
}

void add_ekf(ObserverTypeRegistry& registry) {
  registry.add(observer_type_entry(ObserverTypeDefinition<EkfOptions>{
      .name = "ekf",
      .description = "extended Kalman filter, AD Jacobians",
      .condition = "",
      .keys = kalman_keys({{"sparse_jacobian",
                            "n >= 100: F P F' over F's nonzeros (false: dense products)", "true"}}),
      .parse =
          [](JsonReader& o, const ModelInstance& model) {
            EkfOptions s;
            read_covariances(o, s, model);
            s.sparse_jacobian = o.boolean("sparse_jacobian").value_or(true);
            return s;
          },
      .write =
          [](const EkfOptions& s, nlohmann::json& out) {
            write_covariances(s, out);
            if (!s.sparse_jacobian) out["sparse_jacobian"] = false;
          },
      .build = [](EkfOptions s, const ObserverBuild& b) -> std::unique_ptr<Observer> {
        s.initial_estimate = b.start;
        return std::make_unique<ExtendedKalmanFilter<AnyModel>>(b.design, std::move(s));
      }}));
}

void add_ukf(ObserverTypeRegistry& registry) {
  registry.add(observer_type_entry(ObserverTypeDefinition<UkfOptions>{
      .name = "ukf",
      .description = "unscented Kalman filter, scaled sigma points (no Jacobians)",
      .condition = "",
      .keys = kalman_keys({{"alpha", "sigma-point spread in (0, 1]", "1"},
                           {"beta", "distribution prior, >= 0", "2"},
                           {"kappa", "secondary scaling", "0"}}),
      .parse =
          [](JsonReader& o, const ModelInstance& model) {
            UkfOptions s;
            read_covariances(o, s, model);
            s.alpha = o.number("alpha").value_or(s.alpha);
            s.beta = o.number("beta").value_or(s.beta);
            s.kappa = o.number("kappa").value_or(s.kappa);
            return s;
          },
      .write =
          [](const UkfOptions& s, nlohmann::json& out) {
            write_covariances(s, out);
            out["alpha"] = s.alpha;
            out["beta"] = s.beta;
            out["kappa"] = s.kappa;
          },
      .build = [](UkfOptions s, const ObserverBuild& b) -> std::unique_ptr<Observer> {
        s.initial_estimate = b.start;
        return std::make_unique<UnscentedKalmanFilter<AnyModel>>(b.design, std::move(s));
      }}));
}

}  // namespace

void add_baseline_types(ObserverTypeRegistry& registry) {
  add_luenberger(registry);
  add_sliding_mode(registry);
  add_ekf(registry);
  add_ukf(registry);
}

void add_finite_difference_type(ObserverTypeRegistry& registry) {
  registry.add(observer_type_entry(ObserverTypeDefinition<std::string>{
      .name = "finite_difference",
      .description = "backward differences of y as the state (y, y', ...)",
      .condition = "one output",
      .keys = {{"name", "in reports", "finite_difference"}},
      .parse = [](JsonReader& o,
                  const ModelInstance&) { return o.name().value_or("finite_difference"); },
      .write = [](const std::string& label, nlohmann::json& out) { out["name"] = label; },
      .build = [](const std::string& label, const ObserverBuild& b) -> std::unique_ptr<Observer> {
        const AnyModel& model = b.model.discrete;
        if (model.outputs() != 1) {
          throw InvalidInput(
              "finite_difference needs a model with one output (its state the output's phase "
              "variables y, y', ...)");
        }
        return std::make_unique<FiniteDifferenceObserver>(FiniteDifferenceOptions{
            .name = label, .states = model.states(), .sample_time = model.sample_time()});
      }}));
}

}  // namespace nlobs::detail
