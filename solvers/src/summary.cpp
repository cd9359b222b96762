#include "nlobs/solvers/summary.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace nlobs {
namespace {

std::string sci(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3e", v);
  return buf;
}

bool cut_short(Status s) {
  return s == Status::kMaxIterations || s == Status::kMaxEvaluations || s == Status::kStagnated ||
         s == Status::kRepeatedIterates || s == Status::kRoundingFloor ||
         s == Status::kLocalMinimum || s == Status::kStoppedByCallback;
}

}  // namespace

// Allocation-free: observers call it at every step.
bool Summary::usable() const {
  if (!point_finite || std::isinf(residual_norm)) return false;
  const bool judged = !residual_minimised && std::isfinite(residual_norm);
  // Small enough to use: the tolerance asked for, or acceptance_tolerance if that is looser.
  const double small = std::max(residual_tolerance.value_or(0.0), acceptance_tolerance);
  if (status == Status::kConverged) return !(judged && residual_tolerance && residual_norm > small);
  if (cut_short(status)) return judged && residual_norm <= small;
  return false;
}

std::string Summary::unusable_reason() const {
  if (usable()) return {};
  const std::string status_name(to_string(status));
  const std::string detail = message.empty() ? "" : " (" + message + ")";
  if (status != Status::kConverged && !cut_short(status)) {
    return message.empty() ? status_name : status_name + ": " + message;
  }
  if (!point_finite) return status_name + ": the returned point is not finite";
  if (std::isinf(residual_norm)) return status_name + ": |F| is not finite";
  const bool judged = !residual_minimised && std::isfinite(residual_norm);
  const double small = std::max(residual_tolerance.value_or(0.0), acceptance_tolerance);
  switch (status) {
    case Status::kConverged:
      if (judged && residual_tolerance && residual_norm > small) {
        return "converged by its step with |F| " + sci(residual_norm) + " > " +
               (small == *residual_tolerance ? "residual_tolerance " : "acceptance_tolerance ") +
               sci(small);
      }
      return {};
    case Status::kMaxIterations:
    case Status::kMaxEvaluations:
    case Status::kStagnated:
    case Status::kRepeatedIterates:
    case Status::kRoundingFloor:
    case Status::kLocalMinimum:
    case Status::kStoppedByCallback:
      if (!judged)
        return status_name + " at a point whose residual does not show a solution" + detail;
      if (residual_norm > small) {
        return status_name + " with |F| " + sci(residual_norm) + " > " +
               (small == acceptance_tolerance ? "acceptance_tolerance " : "residual_tolerance ") +
               sci(small) + detail;
      }
      return {};
    default:
      return message.empty() ? status_name : status_name + ": " + message;
  }
}

std::string Summary::brief_report() const {
  std::ostringstream os;
  if (!engine.empty()) os << engine << (stage.empty() ? "" : " (" + stage + ")") << ": ";
  os << to_string(status) << " after " << iterations << " iterations (" << function_evaluations
     << " evaluations";
  if (jacobian_evaluations > 0) os << ", " << jacobian_evaluations << " Jacobians";
  if (linear_iterations > 0) os << ", " << linear_iterations << " linear iterations";
  os << "), |step| " << sci(step_norm);
  if (!std::isnan(residual_norm)) os << ", |F| " << sci(residual_norm);
  if (objective) os << ", f " << sci(*objective);
  if (error_bound)
    os << ", |x-p| <= " << sci(*error_bound) << (lipschitz_is_estimate ? " (est.)" : "");
  return os.str();
}

std::string Summary::full_report() const {
  std::ostringstream os;
  os << "nlobs solver summary\n";
  if (!engine.empty()) os << "  engine                 " << engine << '\n';
  if (!stage.empty()) os << "  answer from stage      " << stage << '\n';
  os << "  status                 " << to_string(status) << '\n';
  if (!library_status.empty()) os << "  library status         " << library_status << '\n';
  if (!message.empty()) os << "  message                " << message << '\n';
  os << "  iterations             " << iterations << '\n'
     << "  function evaluations   " << function_evaluations << '\n'
     << "  jacobian evaluations   " << jacobian_evaluations << '\n';
  if (!linear_solver.empty()) {
    os << "  linear solver          " << linear_solver << " (" << linear_setups << " setups";
    if (linear_iterations > 0) os << ", " << linear_iterations << " Krylov iterations";
    os << ")\n";
  }
  os << "  final step norm        " << sci(step_norm) << '\n'
     << "  final residual norm    " << sci(residual_norm) << '\n';
  if (objective) os << "  objective              " << sci(*objective) << '\n';
  if (contraction_estimate) {
    os << "  contraction estimate   " << sci(*contraction_estimate) << '\n';
  }
  if (lipschitz_constant) {
    os << "  lipschitz constant     " << sci(*lipschitz_constant)
       << (lipschitz_is_estimate ? " (estimated from steps)" : " (given)") << '\n';
  }
  if (error_bound) {
    os << "  error bound            " << sci(*error_bound)
       << (lipschitz_is_estimate ? " (estimate)" : " (guaranteed if L holds)") << '\n';
  }
  if (a_priori_iterations) os << "  a priori iterations    " << *a_priori_iterations << '\n';
  if (!trace.empty()) os << "  trace entries          " << trace.size() << '\n';
  return os.str();
}

}  // namespace nlobs
