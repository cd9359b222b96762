// A model-typed observer type: the extended Kalman filter on the model's own C++ type, so that
// the model's state, f, h and their AD Jacobians are fixed-size Eigen types (2 for
// FitzHugh–Nagumo; the filter's P, Q, R stay run-time matrices) where the built-in "ekf" goes
// through AnyModel's run-time sizes. The same equations as "ekf":
//   x̂⁻ = f(x̂, u),  P⁻ = A P Aᵀ + Q,  K = P⁻ Cᵀ (C P⁻ Cᵀ + R)⁻¹,  x̂ = x̂⁻ + K (y − h(x̂⁻)),
// A = ∂f/∂x, C = ∂h/∂x by AD. The type reaches the model's type through
// nlobs::build_on_model<Models...>: it is built for the plugin's own model and for the built-in
// Lorenz system (whose header nlobs installs), and refused by name on any other model.
// A scenario entry {"type": "fixed_size_ekf", "process_covariance": 1e-8} builds it.
#include <memory>
#include <type_traits>

#include "example_plugin.hpp"
#include "fitzhugh_nagumo.hpp"
#include "nlobs/models/discretization.hpp"
#include "nlobs/models/systems.hpp"
#include "nlobs/observers/baselines/baselines.hpp"

namespace example {
namespace {

// A covariance key: v (for v I) or a matrix of rows, as the built-in "ekf" reads them.
Eigen::MatrixXd covariance(nlobs::JsonReader& o, const std::string& key, Eigen::Index size) {
  if (o.has(key) && o.json()[key].is_number()) {
    return *o.number(key) * Eigen::MatrixXd::Identity(size, size);
  }
  return o.matrix(key).value_or(Eigen::MatrixXd());
}

void write_covariance(const Eigen::MatrixXd& m, const std::string& key, nlohmann::json& out) {
  if (m.size() == 0) return;
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (Eigen::Index j = 0; j < m.cols(); ++j) row.push_back(m(i, j));
    rows.push_back(std::move(row));
  }
  out[key] = std::move(rows);
}

}  // namespace

void add_fixed_size_ekf(nlobs::PluginRegistrar& registrar) {
  registrar.add_observer_type(
      nlobs::observer_type_entry(nlobs::ObserverTypeDefinition<nlobs::EkfOptions>{
          .name = "fixed_size_ekf",
          .description = "extended Kalman filter on the model's own type, fixed-size model "
                         "evaluations (example plugin)",
          .condition = "the model is fitzhugh-nagumo or lorenz",
          .keys = {{"process_covariance", "Q (n x n, or v for v I)", "1e-6 I"},
                   {"measurement_covariance", "R (p x p, or v for v I)", "1e-4 I"},
                   {"initial_covariance", "P0 (n x n, or v for v I)", "I"}},
          .parse =
              [](nlobs::JsonReader& o, const nlobs::ModelInstance& model) {
                nlobs::EkfOptions s;
                s.name = "fixed_size_ekf";
                const Eigen::Index n = model.discrete.states(), p = model.discrete.outputs();
                s.process_covariance = covariance(o, "process_covariance", n);
                s.measurement_covariance = covariance(o, "measurement_covariance", p);
                s.initial_covariance = covariance(o, "initial_covariance", n);
                return s;
              },
          .write =
              [](const nlobs::EkfOptions& s, nlohmann::json& out) {
                write_covariance(s.process_covariance, "process_covariance", out);
                write_covariance(s.measurement_covariance, "measurement_covariance", out);
                write_covariance(s.initial_covariance, "initial_covariance", out);
              },
          // The scenario's model, as its type: the filter is compiled for each type listed here.
          .build = [](nlobs::EkfOptions s,
                      const nlobs::ObserverBuild& b) -> std::unique_ptr<nlobs::Observer> {
            s.initial_estimate = b.start;
            return nlobs::build_on_model<FitzHughNagumo, nlobs::Lorenz>(
                b.model, "fixed_size_ekf", "it is built for fitzhugh-nagumo and lorenz only",
                [&](const auto& model) -> std::unique_ptr<nlobs::Observer> {
                  using Model = std::decay_t<decltype(model)>;
                  using Sampled = nlobs::Discretized<Model>;
                  return std::make_unique<nlobs::ExtendedKalmanFilter<Sampled>>(
                      Sampled(model, b.model.discrete.sample_time(), b.model.discretization), s);
                });
          }}));
}

}  // namespace example
