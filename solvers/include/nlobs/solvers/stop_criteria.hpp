#pragma once
// Stop criteria of [MGFF23] (paper §3.3), selectable and combinable. All norms are max norms.
#include <optional>

namespace nlobs {

enum class Combine {
  kAny,  // converged as soon as one enabled convergence criterion holds
  kAll,  // converged only when every enabled convergence criterion holds
};

struct StopCriteria {
  // Step criterion, eq. (73): ‖x_l − x_{l−1}‖∞ ≤ step_tolerance. 1e-5 reproduces the paper.
  std::optional<double> step_tolerance = 1e-8;
  // The step criterion relative to the iterate: ‖x_l − x_{l−1}‖∞ / (‖x_l‖∞ + 1) ≤ step_tolerance,
  // for unknowns far from 1 in size (a tolerance of 1e-8 on x ~ 1e5 asks for 13 digits). With an
  // engine's scaling (Engine::set_scaling) the norms are of D_u x: close to KINSOL's scaled step
  // test max_i |Δx_i| / (|x_i| + 1/D_u,i), in the max norm of the iterate rather than per
  // component.
  bool relative_step = false;
  // Residual criterion: ‖G(x) − x‖∞ ≤ residual_tolerance (equals ‖F(x)‖∞ for a root problem
  // adapted with Ψ = I), evaluated at the last point where the engine evaluated G.
  std::optional<double> residual_tolerance{};
  // Error-bound criterion, Remark 6: with L the Lipschitz constant of G (max norm),
  // ‖x_l − x_{l−1}‖∞ ≤ (1 − L) ε  ⇒  ‖x_{l−1} − p‖∞ ≤ ε. Enabled when error_tolerance is set.
  std::optional<double> error_tolerance{};
  // L for the error bound and the a priori iteration count ⌈m / log10(1/L)⌉ (eq. 64).
  // When unset, L is estimated from the ratio of consecutive steps (reported as an estimate).
  std::optional<double> lipschitz_constant{};
  Combine combine = Combine::kAny;

  // Stagnation, eq. (72): stop when the step has not shrunk for this many consecutive
  // iterations (1 = the paper's rule, judged on the step alone; 0 = off). If over that stretch
  // the step grew by more than divergence_growth, the run is reported as diverged instead.
  // Above 1 the residual is heard too: a stretch over which ‖F‖∞ fell below 0.999 × its lowest
  // before the stretch is progress, not a verdict (growing steps on the way in to a root).
  // Independent of these options, every engine ends at the rounding floor: three iterations in a
  // row with a full step (not cut short by the engine) ‖Δx‖∞ ≤ 1e4 · ε · (‖x‖∞ + 1) and no
  // such fall of ‖F‖∞ (Status::kRoundingFloor).
  int stagnation_patience = 5;
  double divergence_growth = 10.0;
  // The same two rules for non-monotone engines (Anderson; an accelerator that declares
  // kNonMonotone), whose steps and residuals rise and fall by design: judged by the best residual
  // ‖G(x) − x‖∞ instead of the last step. Stagnated when no residual of the last residual_window
  // iterations is below the smallest before them; diverged when every one of them exceeds
  // divergence_growth × that smallest. 0 = off. The default is long because such runs rise for a
  // long while: on the 2-D Bratu problem (λ = 6, nonlinear Jacobi, Anderson(3) from u = 0) the
  // longest stretch without a new best residual is 7, 44, 196 and 604 iterations at n = 100, 1024,
  // 3025 and 10⁴, and between 2 000 and 5 000 at 99 856 (docs/solvers.md): it grows with the
  // problem's slowest mode, so the window does too.
  int residual_window = 1000;
  // The window in force is max(residual_window, ⌈residual_window_per_unknown · n⌉) for n unknowns:
  // 1000 up to n = 10⁴, 9 986 at 99 856 (where a window of 1000 or 2000 ended Anderson(3)
  // `stagnated` at ‖F‖∞ 1e-5 and 5e-7; from 5000 up it converges, 63 046 iterations). ≥ 0, finite;
  // 0 keeps residual_window alone.
  double residual_window_per_unknown = 0.1;
  // Progress, counted in evaluations, for the engines that solve a square system with a
  // Jacobian (newton, dogleg, levenberg-marquardt, broyden, pseudo-transient; a least-squares
  // minimum has ‖F‖ > 0, and levenberg-marquardt with m > n ends by its function_tolerance):
  // stagnated when progress_window evaluations of F at iterates and trial points (difference
  // evaluations for a Jacobian are not counted) have not brought ‖F‖₂ below 0.999 × its value
  // at the last such fall (0 = off). ‖F‖₂ is the merit function these engines descend (½‖F‖₂²), and
  // a window in evaluations sees the trial steps a trust region rejects, which never reach an
  // iteration count. Without it a run at a local minimum of ‖F‖ spends its whole budget:
  // Levenberg–Marquardt on Powell's badly scaled function from 100 x₀ spent 3000 evaluations at
  // ‖F‖₂ = 1e-4, pseudo-transient on Chebyquad n = 8 4910 while ‖F‖₂ grew to 3.5e29.
  int progress_window = 50;
  // Diverged when ‖x_l‖∞ exceeds divergence_limit · max(1, ‖x_0‖∞).
  double divergence_limit = 1e12;
  // Remark 8: three consecutive equal iterates end the run (status repeated_iterates).
  bool stop_on_repeated_iterates = true;

  // Summary::usable(): the residual ‖F‖∞ (‖G(x) − x‖∞) at or below which an answer may be used
  // even when it was cut short (max iterations or evaluations, stagnation, repeated iterates) or
  // lands above a tighter residual_tolerance. Absolute, in the units of F; raise it for a
  // badly scaled F.
  double acceptance_tolerance = 1e-6;

  int max_iterations = 10000;
  int max_evaluations = 100000;
};

// Throws InvalidInput naming the option and its value (tolerance ≤ 0 or non-finite,
// L ∉ [0, 1), negative patience, growth ≤ 1, limits ≤ 0, ...).
void validate(const StopCriteria& criteria);

// A fall of ‖F‖ counts as progress when it goes below (1 − kMeaningfulResidualFall) × its value at
// the last such fall (not the lowest seen since): at the rounding floor ‖F‖ jitters and sets new
// records by hair's breadths, and a crawl of 1e-4 per evaluation still counts once per eleven.
inline constexpr double kMeaningfulResidualFall = 1e-3;

}  // namespace nlobs
