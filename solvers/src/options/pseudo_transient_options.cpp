// PseudoTransientOptions: validation, description and spec reading (pseudo_transient_engine.hpp).
#include <algorithm>
#include <cmath>

#include "nlobs/solvers/options_validation.hpp"
#include "nlobs/solvers/pseudo_transient_engine.hpp"
#include "nlobs/solvers/sparse_path.hpp"
#include "shared_keys.hpp"

namespace nlobs {

void PseudoTransientOptions::validate() const {
  constexpr const char* kOwner = "PseudoTransientOptions";
  require_option(initial_pseudo_step >= kMinPseudoStep && std::isfinite(initial_pseudo_step),
                 kOwner, "initial_pseudo_step (delta0)", initial_pseudo_step,
                 "must be finite and >= 2.22e-16 (machine epsilon: a smaller pseudo time step is "
                 "lost to rounding, x + delta F == x wherever |F| <= |x|)");
  require_option(max_pseudo_step >= initial_pseudo_step && std::isfinite(max_pseudo_step), kOwner,
                 "max_pseudo_step (delta_max)", max_pseudo_step,
                 "must be finite and >= initial_pseudo_step");
  require_option(min_pseudo_step >= kMinPseudoStep && min_pseudo_step <= initial_pseudo_step,
                 kOwner, "min_pseudo_step", min_pseudo_step,
                 "must lie in [2.22e-16 (machine epsilon), initial_pseudo_step]");
  require_option(pseudo_step_growth >= 1.0 && pseudo_step_growth <= 10.0, kOwner,
                 "pseudo_step_growth (growth)", pseudo_step_growth, "must lie in [1, 10]");
  require_option(linear_tolerance > 0.0 && linear_tolerance < 1.0, kOwner, "linear_tolerance",
                 linear_tolerance, "must lie in (0, 1)");
  detail::check_linear_solver_option("PseudoTransientOptions::linear_solver", linear_solver);
}

EngineDescription PseudoTransientOptions::describe() {
  return {"pseudo-transient",
          "pseudo-transient continuation (Kelley-Keyes): implicit Euler on a flow to the root, "
          "growing step",
          {{"flow", "residual|fixed-point: dx/dt = -F = x - G(x) or G(x) - x; default residual"},
           {"initial_pseudo_step",
            "initial pseudo time step, >= 2.22e-16 (machine epsilon); default 1e-2",
            {"delta0"}},
           {"max_pseudo_step", "largest pseudo time step; default 1e12", {"delta_max"}},
           {"pseudo_step_growth",
            "factor gamma >= 1 on the SER step update (PETSc: 1.1), <= 10; default 1",
            {"growth"}},
           detail::finite_difference_key(),
           detail::linear_solver_key(),
           detail::preconditioner_key(),
           detail::ordering_key()},
          {"pseudo-transient:flow=fixed-point",
           "pseudo-transient:flow=fixed-point,initial_pseudo_step=1e-4",
           "pseudo-transient:flow=fixed-point,linear_solver=gmres,preconditioner=ilu0"}};
}

void PseudoTransientOptions::read(EngineSpecReader& spec) {
  if (auto v = spec.choice("flow", {"residual", "fixed-point"})) {
    flow = *v == "residual" ? Flow::kResidual : Flow::kFixedPoint;
  }
  if (auto v = spec.number("initial_pseudo_step")) initial_pseudo_step = *v;
  if (auto v = spec.number("max_pseudo_step")) max_pseudo_step = *v;
  if (auto v = spec.number("pseudo_step_growth")) pseudo_step_growth = *v;
  // δ_min follows a δ₀ below it (δ₀ itself is checked by validate(): >= ε).
  if (min_pseudo_step > initial_pseudo_step) {
    min_pseudo_step = std::max(initial_pseudo_step, kMinPseudoStep);
  }
  if (auto v = detail::read_finite_difference(spec)) finite_difference = *v;
  if (auto v = detail::read_linear_solver("pseudo-transient", spec, linear_solver)) {
    linear_solver = *v;
  }
}

}  // namespace nlobs
