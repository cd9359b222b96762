// LevenbergMarquardtOptions: validation, description and spec reading
// (levenberg_marquardt_engine.hpp).
#include <cmath>

#include "nlobs/common/invalid_input.hpp"
#include "nlobs/solvers/levenberg_marquardt_engine.hpp"
#include "nlobs/solvers/options_validation.hpp"
#include "shared_keys.hpp"

namespace nlobs {

void LevenbergMarquardtOptions::validate() const {
  constexpr const char* kOwner = "LevenbergMarquardtOptions";
  const auto positive = [&](double value, const char* field) {
    require_option(value > 0.0 && std::isfinite(value), kOwner, field, value,
                   "must be finite and > 0");
  };
  const auto non_negative = [&](double value, const char* field) {
    require_option(value >= 0.0 && std::isfinite(value), kOwner, field, value,
                   "must be finite and >= 0");
  };
  positive(initial_radius_factor, "initial_radius_factor");
  non_negative(function_tolerance, "function_tolerance");
  non_negative(gradient_tolerance, "gradient_tolerance");
  positive(acceleration_ratio, "acceleration_ratio");
  positive(second_derivative_step, "second_derivative_step");
  if (linear_solver != "auto" && linear_solver != "dense" && linear_solver != "cholmod") {
    throw InvalidInput("LevenbergMarquardtOptions::linear_solver = \"" + linear_solver +
                       "\" is invalid: must be auto, dense or cholmod");
  }
}

EngineDescription LevenbergMarquardtOptions::describe() {
  return {
      "levenberg-marquardt",
      "Levenberg-Marquardt as MINPACK lmder (More's lambda and scaling), square or least "
      "squares",
      {{"scaling", "none|jacobian: D = I or Jacobian column norms (More); default none", {"scale"}},
       {"initial_radius_factor", "initial radius factor * |D x0|; default 100", {"factor"}},
       {"geodesic_acceleration",
        "0/1 geodesic acceleration (Transtrum-Sethna); default 0",
        {"geodesic"}},
       // MINPACK's ftol: on this engine `ftol` is this, not the common residual_tolerance.
       {"function_tolerance",
        "relative reduction of |F|^2 (MINPACK's ftol); default 1e-10",
        {"ftol"}},
       {"gradient_tolerance",
        "cosine of F and the columns of J (MINPACK's gtol); default 1e-12",
        {"gtol"}},
       detail::finite_difference_key(),
       {"linear_solver",
        "auto|cholmod|dense: the step of a problem with a sparse Jacobian by CHOLMOD's "
        "sparse Cholesky of the normal equations, or dense QR; default auto (cholmod)",
        {"linear"}}},
      {"levenberg-marquardt", "levenberg-marquardt:geodesic_acceleration=1",
       "levenberg-marquardt:scaling=jacobian", "levenberg-marquardt:linear_solver=dense"}};
}

void LevenbergMarquardtOptions::read(EngineSpecReader& spec) {
  if (auto v = spec.choice("scaling", {"none", "jacobian"})) {
    scale_by_jacobian_columns = *v == "jacobian";
  }
  if (auto v = spec.number("initial_radius_factor")) initial_radius_factor = *v;
  if (auto v = spec.boolean("geodesic_acceleration")) geodesic_acceleration = *v;
  if (auto v = spec.number("function_tolerance")) function_tolerance = *v;
  if (auto v = spec.number("gradient_tolerance")) gradient_tolerance = *v;
  if (auto v = detail::read_finite_difference(spec)) finite_difference = *v;
  if (auto v = spec.text("linear_solver")) linear_solver = *v;
}

}  // namespace nlobs
