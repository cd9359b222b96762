#pragma once
// KINSOL (SUNDIALS) as a reference solver for the same problems our engines solve: fixed
// point, fixed point with Anderson acceleration, Newton with line search and a dense direct
// linear solver. KINSOL is set up once in the constructor and re-run by solve(), so a timing
// of solve() measures the iteration, not the set-up — the same treatment our engines get.
#include <Eigen/Core>
#include <functional>
#include <memory>
#include <optional>
#include <string>

namespace nlobs::reference {

enum class KinsolStrategy {
  kFixedPoint,          // "kinsol:fp"      KIN_FP, G given
  kFixedPointAnderson,  // "kinsol:fp-aa2"  KIN_FP with Anderson depth anderson_depth
  kNewtonLineSearch,    // "kinsol:newton"  KIN_LINESEARCH, F and its Jacobian given
};

struct KinsolOptions {
  KinsolStrategy strategy = KinsolStrategy::kFixedPoint;
  double tolerance = 1e-8;  // KINSOL's fnormtol (‖F‖∞, or ‖G(u)−u‖∞ for FP) and scsteptol
  int anderson_depth = 2;
  long max_iterations = 10000;  // KINSetNumMaxIters: KINSOL counts iterations, not evaluations
  // Every evaluation of F (or G) counts, the final check's included (KinsolResult::evaluations):
  // KINSOL may make max_evaluations − 1 — its line search and difference-quotient Jacobian
  // evaluate F more than once per iteration, which max_iterations does not bound — and the check
  // takes the last one. An evaluation beyond that is refused before F is called (the callback
  // returns −1: KINSOL stops with KIN_SYSFUNC_FAIL or a linear-solver failure) and the status is
  // "max_evaluations". 0: no limit; otherwise at least 2.
  long max_evaluations = 0;
  // KINSetMaxNewtonStep (Newton only): the largest scaled step ‖Δu‖₂. 0 keeps KINSOL's rule,
  // 1000 ‖u₀‖₂ but at least 1 (kinsol.c, KINSolInit), which at u₀ = 0 allows steps of length 1
  // only and ends runs with KIN_MXNEWT_5X_EXCEEDED; the suite passes 1000 max(1, ‖u₀‖₂).
  double max_newton_step = 0.0;
  // KINSol's u_scale and f_scale: its norms, fnormtol's test and the check below included, are
  // those of D_u Δu and D_f F (D = diag(scale)). Empty: ones; otherwise of size n, finite, > 0.
  Eigen::VectorXd u_scale{}, f_scale{};
};

struct KinsolResult {
  int flag = 0;           // KINSol's return flag
  std::string flag_name;  // KINGetReturnFlagName
  // flag >= 0 (KIN_SUCCESS, KIN_INITIAL_GUESS_OK, KIN_STEP_LT_STPTOL) and the returned u is
  // finite with ‖F(u)‖∞ ≤ tolerance (‖G(u) − u‖∞ for FP), checked by one more evaluation:
  // KINSOL's fixed-point iteration reports KIN_SUCCESS on a step test alone, even for a u that
  // overflowed or is NaN.
  bool success = false;
  // Why success is false although flag >= 0: "returned a point that is not finite" or
  // "|F| 300 > tolerance 1e-08".
  std::string reason;
  double residual = 0.0;  // ‖D_f F(u)‖∞ (‖D_f (G(u) − u)‖∞ for FP) at the returned u
  long iterations = 0;    // KINGetNumNonlinSolvIters
  // Every evaluation of F (or G): KINSOL's own, those of its difference-quotient Jacobian
  // (KINGetNumFuncEvals leaves them out) and the final check above, counted at the callback,
  // so the column compares with our engines' function_evaluations.
  long evaluations = 0;
  long jacobian_evaluations = 0;  // KINGetNumJacEvals (Newton only)
  bool budget_spent = false;      // an evaluation beyond max_evaluations was refused
  // "converged", "non_finite" or "residual_above_tolerance" (flag >= 0 that does not stand);
  // "max_evaluations" (budget_spent), "max_iterations" (KIN_MAXITER_REACHED), "non_finite"
  // (KIN_FIRST_SYSFUNC_ERR, KIN_REPTD_SYSFUNC_ERR: F not finite where KINSOL could not avoid
  // it), else KINSOL's flag name in lowercase (kin_linesearch_nonconv, kin_mxnewt_5x_exceeded,
  // ...; kin_flag_<number> for a flag this version does not name).
  std::string status() const;
};

class KinsolSolver {
 public:
  using Function = std::function<void(const Eigen::VectorXd&, Eigen::VectorXd&)>;
  using Jacobian = std::function<void(const Eigen::VectorXd&, Eigen::MatrixXd&)>;

  // For fixed-point strategies `function` is G; for Newton it is F and `jacobian` its
  // Jacobian (empty: KINSOL's difference quotients).
  KinsolSolver(int n, KinsolOptions options, Function function, Jacobian jacobian = {});
  ~KinsolSolver();
  KinsolSolver(const KinsolSolver&) = delete;
  KinsolSolver& operator=(const KinsolSolver&) = delete;

  // x: initial guess in, KINSOL's answer out.
  KinsolResult solve(Eigen::VectorXd& x);

  static std::string name(KinsolStrategy strategy);
  // The inverse of name(): "kinsol:fp", "kinsol:fp-aa2", "kinsol:newton"; none for another.
  static std::optional<KinsolStrategy> strategy(const std::string& name);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace nlobs::reference
