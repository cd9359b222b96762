// CeresOptions: validation, description and spec reading (ceres_engine.hpp).
#include "nlobs/common/invalid_input.hpp"
#include "nlobs/solvers/box_bounds.hpp"
#include "nlobs/solvers/ceres_engine.hpp"
#include "nlobs/solvers/options_validation.hpp"

namespace nlobs {

void CeresOptions::validate() const {
  require_option(function_tolerance >= 0.0, "CeresOptions", "function_tolerance",
                 function_tolerance, "must be >= 0");
  require_option(gradient_tolerance >= 0.0, "CeresOptions", "gradient_tolerance",
                 gradient_tolerance, "must be >= 0");
  if (backend == Backend::kTinySolver) {
    if (lower_bounds.size() > 0 || upper_bounds.size() > 0) {
      throw InvalidInput("CeresOptions::backend = kTinySolver does not support bounds");
    }
    if (method != Method::kLevenbergMarquardt) {
      throw InvalidInput("CeresOptions::backend = kTinySolver is Levenberg-Marquardt only");
    }
  }
  detail::validate_box("CeresOptions", lower_bounds, upper_bounds);
}

EngineDescription CeresOptions::describe() {
  return {"ceres",
          "Ceres least squares, Levenberg-Marquardt or dogleg",
          {{"<lm|dogleg>", "trust-region strategy; default lm"},
           {"backend", "auto|tiny|solver; default auto"},
           {"function_tolerance", "relative cost change; default 1e-10", {"function_tol"}},
           {"gradient_tolerance", "default 1e-12", {"gradient_tol"}},
           {"jacobi_scaling", "0/1 Jacobi scaling (solver backend); default 0", {"jacobi"}},
           {"nonmonotonic_steps",
            "0/1 non-monotonic steps (solver backend); default 1",
            {"nonmonotonic"}}},
          {"ceres", "ceres:dogleg", "ceres:lm,backend=solver"}};
}

void CeresOptions::read(EngineSpecReader& spec) {
  if (auto w = spec.word({"lm", "dogleg"})) {
    method = *w == "dogleg" ? Method::kDogleg : Method::kLevenbergMarquardt;
  }
  if (auto v = spec.choice("backend", {"auto", "tiny", "solver"})) {
    backend = *v == "auto"   ? Backend::kAuto
              : *v == "tiny" ? Backend::kTinySolver
                             : Backend::kSolver;
  }
  if (auto v = spec.number("function_tolerance")) function_tolerance = *v;
  if (auto v = spec.number("gradient_tolerance")) gradient_tolerance = *v;
  if (auto v = spec.boolean("jacobi_scaling")) jacobi_scaling = *v;
  if (auto v = spec.boolean("nonmonotonic_steps")) nonmonotonic_steps = *v;
}

}  // namespace nlobs
