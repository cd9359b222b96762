#include "list_command.hpp"

#include <ostream>
#include <stdexcept>

#include "model_catalog.hpp"
#include "nlobs/solvers/engine_registry.hpp"
#include "pi_banks.hpp"
#include "reference/mgh_suite.hpp"
#include "scenario.hpp"
#include "solve_chua_window.hpp"

namespace nlobs::cli {

void print_list(const std::string& what, std::ostream& out) {
  const bool all = what.empty();
  if (!all && what != "engines" && what != "models" && what != "observers" && what != "scenarios") {
    throw std::invalid_argument("nothing to list under '" + what +
                                "'; valid: models, engines, observers, scenarios");
  }
  if (all || what == "models") {
    out << "models (JSON: {\"name\", \"parameters\", \"scheme\": euler|rk4, \"step\"}):\n";
    for (const auto& m : model_catalog()) {
      out << "  " << m.name << " — " << m.description << '\n';
      if (!m.parameters.empty()) {
        out << "      parameters:";
        for (const auto& p : m.parameters) out << ' ' << p;
        out << '\n';
      }
    }
  }
  if (all || what == "observers") {
    out << "observers (scenario \"observers\" entries):\n"
        << "  window — any engine x output window: engine, tol, window (N; 0 = square), "
           "warm_start (propagated|previous), psi (auto|identity|newton|a number: the square "
           "window's gain)\n"
        << "  luenberger — constant gain: gain (n x p)\n"
        << "  sliding_mode — Q, R (n x p), gamma (saturation boundary layer)\n"
        << "  ekf — extended Kalman filter, AD Jacobians: process_covariance, "
           "measurement_covariance, initial_covariance\n"
        << "  (luenberger, sliding_mode, ekf also take 'model': their own design model)\n"
        << "  pi_bank — model-free PI observers of [FFMG19]: bank, gains ([k_p, k_i] per "
           "channel), omega_bounds ({channel: N}), start (paper|zero), substeps, parameters\n"
        << "  mvt — mean-value-theorem observer of [BMH], models with y = [I_m 0] x: "
           "error_guess (required), name, variant (injection|published), injection_gain, eta, "
           "beta_solver (per-row|nlopt|ceres), integrator (rk4|dopri5), substeps, initial\n"
        << "  high_gain — high-gain observer in embedded coordinates of [HG-EMB23], autonomous "
           "one-output models: N, theta, poles | coefficients, map (ad|explicit), alpha "
           "(auto|explicit|lie), inverse, saturation ({P | P_diagonal | box, R, rho}), "
           "projection (engine spec), start (previous|predicted), integrator (auto|rk4|cvode), "
           "substeps, jump_threshold, observability_floor, residual_scale, restart_residual, "
           "restart_every, "
           "initial_z | initial_z_from, initial, name\n"
        << "  modulating — modulating-function algebraic observer of [MF-LTV], models with a "
           "canonical form (lti-injection, pendulum): horizon, order, degree, noise_weights, "
           "engine, quadrature (simpson|trapezoid), sample_period (0: every sample), resample, "
           "disturbance_bound, initial, name\n"
        << "  finite_difference — backward differences of y as (y, y', ...): name\n";
    for (const auto& b : pi_bank_catalog()) {
      out << "      bank " << b.name << ": " << b.description << "; channels";
      for (const auto& c : b.channels) out << ' ' << c;
      if (!b.parameters.empty()) {
        out << "; parameters";
        for (const auto& p : b.parameters) out << ' ' << p;
      }
      out << '\n';
    }
  }
  if (all || what == "scenarios") {
    out << "scenarios (nlobs run NAME, or a JSON file):\n";
    for (const auto& s : builtin_scenarios()) out << "  " << s << '\n';
  }
  if (!all && what != "engines") return;
  out << "engines (spec: name[:word][,key=value...]):\n";
  for (const auto& e : EngineRegistry<Dynamic>::global().entries()) {
    out << "  " << e.name << " — " << e.description << '\n';
    for (const auto& o : e.options) out << "      " << o.key << ": " << o.description << '\n';
    out << "      e.g.";
    for (const auto& x : e.examples) out << ' ' << x;
    out << '\n';
  }
  out << "  options of every engine:";
  for (const auto& o : EngineRegistry<Dynamic>::global().common_options()) {
    out << "\n      " << o.key << ": " << o.description;
  }
  out << "\nreference solvers (same run, for comparison):\n  solve chua-window:";
  for (const auto& r : reference_names()) out << ' ' << r;
  out << "\n  suite mgh:";
  for (const auto& r : reference::reference_suite_solvers()) out << ' ' << r;
  out << '\n';
}

}  // namespace nlobs::cli
