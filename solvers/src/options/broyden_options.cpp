// BroydenOptions: validation, description and spec reading (broyden_engine.hpp).
#include "nlobs/common/invalid_input.hpp"
#include "nlobs/solvers/broyden_engine.hpp"
#include "nlobs/solvers/linear/make_linear_solver.hpp"
#include "nlobs/solvers/options_validation.hpp"
#include "shared_keys.hpp"

namespace nlobs {

void BroydenOptions::validate() const {
  constexpr const char* kOwner = "BroydenOptions";
  require_option(max_backtracks >= 0 && max_backtracks <= 60, kOwner, "max_backtracks",
                 max_backtracks, "must lie in 0..60");
  require_option(sufficient_decrease > 0.0 && sufficient_decrease < 0.5, kOwner,
                 "sufficient_decrease", sufficient_decrease, "must lie in (0, 0.5)");
  require_option(max_updates >= 0, kOwner, "max_updates", max_updates, "must be >= 0");
  require_option(memory >= 1 && memory <= 1000, kOwner, "memory", memory, "must lie in 1..1000");
  detail::check_linear_solver_option("BroydenOptions::linear_solver", linear_solver);
  if (linear_solver != "auto" && linear_solver != "dense" &&
      make_linear_solver(linear_solver)->iterative()) {
    throw InvalidInput("BroydenOptions::linear_solver = \"" + linear_solver +
                       "\" is invalid: H_0 = J^-1 must be applied exactly, by a direct solver "
                       "(auto, band-lu, sparse-lu, klu, umfpack) or dense");
  }
}

EngineDescription BroydenOptions::describe() {
  return {"broyden",
          "Broyden's good method: line search, Jacobian restarts, O(n^2) inverse updates "
          "(limited memory, O(k n), on a sparse Jacobian)",
          {{"max_backtracks",
            "step halvings before the Jacobian is renewed, 0..60; default 10",
            {"backtracks"}},
           {"max_updates",
            "updates before a fresh Jacobian regardless, 0 = off; default 0",
            {"updates"}},
           detail::finite_difference_key(),
           {"linear_solver",
            "auto|dense|band-lu|sparse-lu|klu|umfpack: H0 = J^-1 of a problem with a sparse "
            "Jacobian by this direct solver, the updates kept as vectors (limited memory), or "
            "dense H; default auto",
            {"linear"}},
           detail::ordering_key(),
           {"memory",
            "updates the limited-memory form keeps before a fresh Jacobian, 1..1000; "
            "default 20"}},
          {"broyden", "broyden:finite_difference=forward,max_updates=20", "broyden:memory=50"}};
}

void BroydenOptions::read(EngineSpecReader& spec) {
  if (auto v = spec.integer("max_backtracks", 0, 60)) max_backtracks = *v;
  if (auto v = spec.integer("max_updates", 0, 1 << 30)) max_updates = *v;
  if (auto v = spec.integer("memory", 1, 1000)) memory = *v;
  if (auto v = spec.text("preconditioner")) {
    throw InvalidInput("broyden: preconditioner=" + *v +
                       " does not apply: H0 is applied by a direct solver "
                       "(linear=auto|band-lu|sparse-lu|klu|umfpack)");
  }
  if (auto v = detail::read_linear_solver("broyden", spec, linear_solver)) linear_solver = *v;
  if (auto v = detail::read_finite_difference(spec)) finite_difference = *v;
}

}  // namespace nlobs
