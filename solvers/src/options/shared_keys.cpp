#include "shared_keys.hpp"

#include "nlobs/common/invalid_input.hpp"

namespace nlobs::detail {

EngineOptionInfo finite_difference_key() {
  return {
      "finite_difference", "forward|central differences when no Jacobian; default central", {"fd"}};
}

EngineOptionInfo linear_solver_key() {
  return {"linear_solver",
          "auto|dense|band-lu|sparse-lu|klu|umfpack|gmres|bicgstab: the linear solver of a "
          "problem with a sparse Jacobian; default auto (band-lu, klu, or umfpack from 20000 "
          "unknowns)",
          {"linear"}};
}

EngineOptionInfo preconditioner_key() {
  return {"preconditioner",
          "none|jacobi|ilu0|ilut|boomeramg, with linear_solver=gmres|bicgstab; default none"};
}

EngineOptionInfo ordering_key() {
  return {"ordering", "amd|metis (nested dissection), with linear_solver=umfpack; default amd"};
}

std::optional<FiniteDifference> read_finite_difference(EngineSpecReader& spec) {
  const auto v = spec.choice("finite_difference", {"forward", "central"});
  if (!v) return std::nullopt;
  return *v == "forward" ? FiniteDifference::kForward : FiniteDifference::kCentral;
}

std::optional<std::string> read_linear_solver(const char* engine, EngineSpecReader& spec,
                                              std::string linear) {
  const std::optional<std::string> given = spec.text("linear_solver");
  if (given) linear = *given;
  const std::optional<std::string> preconditioner = spec.text("preconditioner");
  if (preconditioner) {
    if (linear != "gmres" && linear != "bicgstab") {
      throw InvalidInput(std::string(engine) + ": preconditioner=" + *preconditioner +
                         " needs linear_solver=gmres or bicgstab");
    }
    linear += ":preconditioner=" + *preconditioner;
  }
  const std::optional<std::string> ordering = spec.text("ordering");
  if (ordering) {
    if (linear != "umfpack") {
      throw InvalidInput(std::string(engine) + ": ordering=" + *ordering +
                         " needs linear_solver=umfpack");
    }
    linear += ":ordering=" + *ordering;
  }
  if (!given && !preconditioner && !ordering) return std::nullopt;
  return linear;
}

}  // namespace nlobs::detail
