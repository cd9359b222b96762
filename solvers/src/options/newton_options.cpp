// NewtonOptions: validation, description and spec reading (newton_engine.hpp).
#include "nlobs/common/invalid_input.hpp"
#include "nlobs/solvers/newton_engine.hpp"
#include "nlobs/solvers/options_validation.hpp"
#include "shared_keys.hpp"

namespace nlobs {

void NewtonOptions::validate() const {
  constexpr const char* kOwner = "NewtonOptions";
  require_option(sufficient_decrease > 0.0 && sufficient_decrease < 0.5, kOwner,
                 "sufficient_decrease", sufficient_decrease, "must lie in (0, 0.5)");
  require_option(backtrack_factor > 0.0 && backtrack_factor < 1.0, kOwner, "backtrack_factor",
                 backtrack_factor, "must lie in (0, 1)");
  require_option(max_backtracks >= 1, kOwner, "max_backtracks", max_backtracks, "must be >= 1");
  require_option(jacobian_reuse >= 1 && jacobian_reuse <= 1000, kOwner, "jacobian_reuse",
                 jacobian_reuse, "must lie in 1 .. 1000");
  if (jacobian_reuse > 1 && trust_region) {
    throw InvalidInput(
        "NewtonOptions: jacobian_reuse > 1 (modified Newton) is for the line search or the "
        "plain step; the trust region evaluates J at every iterate");
  }
  static_cast<void>(ForcingTerm(forcing));  // ForcingTermOptions' own checks
  detail::check_linear_solver_option("NewtonOptions::linear_solver", linear_solver);
  if (line_search && trust_region) {
    throw InvalidInput(
        "NewtonOptions: line_search and trust_region are two globalisations; choose one");
  }
}

EngineDescription NewtonOptions::describe() {
  return {"newton",
          "Newton on F = G - x, any Jacobian source",
          {{"line_search", "0/1 Armijo backtracking; default 0", {"linesearch"}},
           {"trust_region",
            "0/1 dogleg trust region, a Jacobian every iterate; default 0",
            {"trustregion"}},
           detail::finite_difference_key(),
           detail::linear_solver_key(),
           detail::preconditioner_key(),
           detail::ordering_key(),
           {"jacobian_reuse",
            "1..1000 iterations one Jacobian (and its factorisation) serves: modified Newton "
            "(KINSOL: 10); default 1",
            {"reuse"}}},
          {"newton", "newton:line_search=1", "newton:trust_region=1",
           "newton:line_search=1,linear_solver=gmres,preconditioner=ilu0",
           "newton:line_search=1,jacobian_reuse=10"}};
}

void NewtonOptions::read(EngineSpecReader& spec) {
  if (auto v = spec.boolean("line_search")) line_search = *v;
  if (auto v = spec.boolean("trust_region")) trust_region = *v;
  if (auto v = spec.integer("jacobian_reuse", 1, 1000)) jacobian_reuse = *v;
  if (auto v = detail::read_finite_difference(spec)) finite_difference = *v;
  if (auto v = detail::read_linear_solver("newton", spec, linear_solver)) linear_solver = *v;
}

}  // namespace nlobs
