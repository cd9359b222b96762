// The moving-horizon estimator on the discretised model (AD Jacobians through AnyModel): the
// scenario key `mhe`. Bounds are arrays where null means no bound on that component.
#include <limits>

#include "builtin_observer_types.hpp"
#include "covariance_keys.hpp"
#include "nlobs/observers/core/any_model.hpp"
#include "nlobs/observers/mhe/mhe_estimator.hpp"

namespace nlobs::detail {
namespace {

nlohmann::json bounds_json(const Eigen::VectorXd& b) {
  nlohmann::json out = nlohmann::json::array();
  for (Eigen::Index i = 0; i < b.size(); ++i) {
    if (std::isfinite(b[i])) {
      out.push_back(b[i]);
    } else {
      out.push_back(nullptr);
    }
  }
  return out;
}

}  // namespace

void add_mhe_type(ObserverTypeRegistry& registry) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  registry.add(observer_type_entry(ObserverTypeDefinition<MheOptions>{
      .name = "mhe",
      .description = "moving-horizon estimation: arrival cost, process noise, state bounds",
      .condition = "",
      .keys = kalman_keys(
          {{"name", "in reports (two MHEs in one scenario need two names)", "mhe"},
           {"horizon", "N >= 1 samples in the window", "10"},
           {"lower_bounds", "l <= x_i (n numbers, null = none)", "none"},
           {"upper_bounds", "x_i <= u (n numbers, null = none)", "none"},
           {"max_iterations", "Gauss-Newton iterations per sample, >= 1", "100"},
           {"real_time_iteration", "one Gauss-Newton iteration per sample", "false"},
           {"step_tolerance", "converged when |dz| <= tol (1 + |z|), > 0", "1e-10"},
           {"cost_tolerance", "converged when the step's decrease <= tol V, > 0", "1e-12"}}),
      .parse =
          [](JsonReader& o, const ModelInstance& model) {
            MheOptions s;
            s.name = o.name().value_or(s.name);
            read_covariances(o, s, model);
            s.horizon = o.integer("horizon", 1, 100000).value_or(s.horizon);
            s.lower_bounds = o.bounds("lower_bounds", -kInf).value_or(Eigen::VectorXd());
            s.upper_bounds = o.bounds("upper_bounds", kInf).value_or(Eigen::VectorXd());
            s.max_iterations = o.integer("max_iterations", 1, 100000).value_or(s.max_iterations);
            s.real_time_iteration = o.boolean("real_time_iteration").value_or(false);
            s.step_tolerance = o.number("step_tolerance").value_or(s.step_tolerance);
            s.cost_tolerance = o.number("cost_tolerance").value_or(s.cost_tolerance);
            return s;
          },
      .write =
          [](const MheOptions& s, nlohmann::json& out) {
            out["name"] = s.name;
            write_covariances(s, out);
            out["horizon"] = s.horizon;
            if (s.lower_bounds.size()) out["lower_bounds"] = bounds_json(s.lower_bounds);
            if (s.upper_bounds.size()) out["upper_bounds"] = bounds_json(s.upper_bounds);
            out["max_iterations"] = s.max_iterations;
            out["real_time_iteration"] = s.real_time_iteration;
            out["step_tolerance"] = s.step_tolerance;
            out["cost_tolerance"] = s.cost_tolerance;
          },
      .build = [](MheOptions s, const ObserverBuild& b) -> std::unique_ptr<Observer> {
        s.initial_estimate = b.start;
        return std::make_unique<MheEstimator<AnyModel>>(b.design, std::move(s));
      }}));
}

}  // namespace nlobs::detail
