// HighGainOptions::validate() and the default projection's solver options, compiled once
// (the observer itself is a template over the model).
#include <string>

#include "nlobs/observers/high_gain/high_gain_observer.hpp"

namespace nlobs {

void HighGainOptions::validate() const {
  constexpr const char* who = "HighGainOptions";
  detail::require_name(who, name);
  detail::require_finite(who, "initial_estimate", initial_estimate);
  if (initial_embedded_estimate) {
    detail::require_finite(who, "initial_embedded_estimate", *initial_embedded_estimate);
  }
  if (!design.map) detail::invalid_option(who, "design.map", "be given (q_N)", "none");
  const Eigen::Index N = design.map->dimension();
  if (N < 2) {
    detail::invalid_option(who, "design.map", "have N >= 2 (q_N cannot be injective otherwise)",
                           "N = " + std::to_string(N));
  }
  if (!design.alpha.value && !design.map->has_next()) {
    detail::invalid_option(who, "design.alpha",
                           "be given when the map cannot evaluate L_f^N h (build the map from the "
                           "model, e.g. LieObservabilityMap, for α = L_f^N h)",
                           "no α, map '" + design.map->description() + "'");
  }
  detail::require_positive(who, "theta", theta);
  detail::require_positive(who, "sample_time", sample_time);
  detail::require_at_least(who, "substeps", static_cast<long>(substeps), 1L);
  detail::require_positive(who, "absolute_tolerance", absolute_tolerance);
  detail::require_positive(who, "relative_tolerance", relative_tolerance);
  // +∞ is meaningful for these two: never count a jump; α = L_f^N h weighted 0 (the chain alone).
  if (!(jump_threshold > 0.0)) {
    detail::invalid_option(who, "jump_threshold", "be > 0 (+inf: count no jump)",
                           detail::option_value(jump_threshold));
  }
  if (!(observability_floor >= 0.0)) {
    detail::invalid_option(who, "observability_floor", "be >= 0 (+inf: the chain without α)",
                           detail::option_value(observability_floor));
  }
  detail::require_positive(who, "residual_scale", residual_scale);
  detail::require_non_negative(who, "restart_residual", restart_residual);
  detail::require_at_least(who, "restart_every", static_cast<long>(restart_every), 1L);
  if (saturation) {
    try {
      saturation->validate(N);
    } catch (const InvalidInput& e) {
      throw InvalidInput(std::string(who) + "::saturation: " + e.what());
    }
  }
}

SolverOptions high_gain_projection_options() {
  SolverOptions solver;
  solver.stop.step_tolerance = 1e-12;
  solver.stop.residual_tolerance = 1e-13;
  solver.stop.max_iterations = 100;
  return solver;
}

}  // namespace nlobs
