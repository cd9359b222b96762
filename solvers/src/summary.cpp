#include "nlobs/solvers/summary.hpp"

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

}  // namespace

std::string Summary::brief_report() const {
  std::ostringstream os;
  if (!engine.empty()) os << engine << ": ";
  os << to_string(status) << " after " << iterations << " iterations (" << function_evaluations
     << " evaluations";
  if (jacobian_evaluations > 0) os << ", " << jacobian_evaluations << " Jacobians";
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
  os << "  status                 " << to_string(status) << '\n';
  if (!message.empty()) os << "  message                " << message << '\n';
  os << "  iterations             " << iterations << '\n'
     << "  function evaluations   " << function_evaluations << '\n'
     << "  jacobian evaluations   " << jacobian_evaluations << '\n'
     << "  final step norm        " << sci(step_norm) << '\n'
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
