// An observer type: output injection into the measured coordinates, a Luenberger observer
//   x̂_{k+1} = f(x̂_k, u_k) + L (y_k − h(x̂_k)),   L = g [I_p; 0] (n × p),
// for models whose outputs are their first p states; the unmeasured states follow the model
// (they converge where the model's own dynamics contract them, e.g. FitzHugh–Nagumo's slow x2,
// at rate ε b). A scenario entry {"type": "output_injection", "gain": 0.5} builds it;
// `nlobs list observers` shows its key. The observer is nlobs' own; the type (its JSON, its
// condition, its build) is the plugin's.
#include <cmath>
#include <memory>

#include "example_plugin.hpp"
#include "nlobs/observers/baselines/baselines.hpp"

namespace example {

void add_output_injection(nlobs::PluginRegistrar& registrar) {
  registrar.add_observer_type(nlobs::observer_type_entry(nlobs::ObserverTypeDefinition<double>{
      .name = "output_injection",
      .description = "Luenberger observer with L = g [I; 0]: injection into the measured "
                     "states (example plugin)",
      .condition = "outputs <= states (meant for y = the first p states)",
      .keys = {{"gain", "g in L = g [I; 0]", "0.5"}},
      .parse =
          [](nlobs::JsonReader& o, const nlobs::ModelInstance& model) {
            const double g = o.number("gain").value_or(0.5);
            if (!std::isfinite(g)) o.fail("'gain' must be a finite number");
            if (model.discrete.outputs() > model.discrete.states()) {
              o.fail("output_injection needs outputs <= states; the model has " +
                     std::to_string(model.discrete.outputs()) + " outputs and " +
                     std::to_string(model.discrete.states()) + " states");
            }
            return g;
          },
      .write = [](const double& g, nlohmann::json& out) { out["gain"] = g; },
      .build = [](const double& g,
                  const nlobs::ObserverBuild& b) -> std::unique_ptr<nlobs::Observer> {
        const Eigen::Index n = b.design.states(), p = b.design.outputs();
        nlobs::LuenbergerOptions o;
        o.name = "output_injection";
        o.initial_estimate = b.start;
        o.gain = Eigen::MatrixXd::Zero(n, p);
        o.gain.topRows(p) = g * Eigen::MatrixXd::Identity(p, p);
        return std::make_unique<nlobs::LuenbergerObserver<nlobs::AnyModel>>(b.design, o);
      }}));
}

}  // namespace example
