#pragma once
// KINSOL (SUNDIALS) as a reference solver for the same problems our engines solve: fixed
// point, fixed point with Anderson acceleration, Newton with line search on a dense, band, KLU or
// SPGMR linear solver. KINSOL is set up once in the constructor and re-run by solve(), so a
// timing of solve() measures the iteration, not the set-up — the same treatment our engines get.
#include <Eigen/Core>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace nlobs::reference {

enum class KinsolStrategy {
  kFixedPoint,          // "kinsol:fp"      KIN_FP, G given
  kFixedPointAnderson,  // "kinsol:fp-aa2"  KIN_FP with Anderson depth anderson_depth
  kNewtonLineSearch,    // "kinsol:newton…" KIN_LINESEARCH on KinsolOptions::linear_solver
};

// The linear solver of KIN_LINESEARCH, each set up as KINSOL's own example drivers set it up.
enum class KinsolLinearSolver {
  kDense,  // "kinsol:newton"        SUNLinSol_Dense; the Jacobian given (else KINSOL's DQ)
  // "kinsol:newton-band"   SUNLinSol_Band on SUNBandMatrix(n, upper, lower) with KINSOL's own
  // difference-quotient band Jacobian (lower + upper + 1 evaluations of F), as kinLaplace_bnd
  kBand,
  // "kinsol:newton-klu"    SUNLinSol_KLU on a CSR SUNSparseMatrix; the sparse Jacobian given
  // (KINSOL has no difference quotients for a sparse matrix)
  kKlu,
  // "kinsol:newton-spgmr"  SUNLinSol_SPGMR, no preconditioner, KINSOL's difference-quotient J·v,
  // Krylov dimension 15 and 2 restarts, as kinFoodWeb_kry
  kSpgmr,
};

// ∂F as compressed sparse rows for kKlu: the pattern once (row_starts of size n + 1, columns
// sorted within a row), and `values(x, f, v)` writing the nnz values in that order at x, where
// f = F(x).
struct KinsolSparseJacobian {
  std::vector<long> row_starts{}, columns{};
  std::function<void(const Eigen::VectorXd& x, const Eigen::VectorXd& f, double* values)> values{};
};

// A preconditioner for kSpgmr, applied on the right (KINSetPreconditioner; SUN_PREC_RIGHT), as
// KINSOL's Krylov examples give one. `setup` prepares P ≈ J at u (f = F(u), and the scales);
// `solve` overwrites v with P⁻¹ v. Each returns 0 on success, > 0 for a recoverable failure
// (KINSOL retries with a fresh setup), < 0 to stop. Neither may throw (a throw is a failure < 0).
struct KinsolPreconditioner {
  using ConstVector = Eigen::Map<const Eigen::VectorXd>;
  std::function<int(ConstVector u, ConstVector u_scale, ConstVector f, ConstVector f_scale)>
      setup{};
  std::function<int(ConstVector u, ConstVector u_scale, ConstVector f, ConstVector f_scale,
                    Eigen::Map<Eigen::VectorXd> v)>
      solve{};
};

struct KinsolOptions {
  KinsolStrategy strategy = KinsolStrategy::kFixedPoint;
  KinsolLinearSolver linear_solver = KinsolLinearSolver::kDense;  // Newton only
  // kBand: J_ij = 0 for i − j > lower_bandwidth or j − i > upper_bandwidth; each in 0 .. n − 1,
  // and the band's storage, n (2 lower + upper + 1) doubles, at most 1.25e8 (1 GB).
  long lower_bandwidth = 0, upper_bandwidth = 0;
  // KINSetMaxSetupCalls (Newton): the Jacobian and its factorisation are renewed at least every
  // this many iterations. 1: exact Newton, what "kinsol:newton" runs; 0: KINSOL's default, 10
  // (modified Newton, with its own tests for renewing earlier), what the band, KLU and SPGMR
  // forms run.
  long max_setup_calls = 1;
  // KINSetMaxSubSetupCalls: how often (in iterations) modified Newton tests whether to renew the
  // Jacobian early; 0: KINSOL's default, 5.
  long max_sub_setup_calls = 0;
  double tolerance = 1e-8;  // KINSOL's fnormtol (‖F‖∞, or ‖G(u)−u‖∞ for FP) and scsteptol
  // KINSetScaledStepTol when > 0 (else `tolerance`): a run ends when max_i |Δu_i| / (|u_i| +
  // 1/D_u,i) falls to it (KINSOL's scaled step, KINScSNorm); also the line search's smallest λ.
  double step_tolerance = 0.0;
  // Newton only (false is refused for the fixed-point strategies): KIN_LINESEARCH (true), or
  // KIN_NONE (false: full Newton steps, which KINSOL shortens only to keep the constraints and to
  // max_newton_step, as kinFoodWeb_kry runs).
  bool line_search = true;
  // KINSetConstraints (Newton only): per unknown 0 (none), 1 (u ≥ 0), 2 (u > 0), −1 (u ≤ 0) or
  // −2 (u < 0). Empty: none; otherwise of size n, each of those values.
  Eigen::VectorXd constraints{};
  // kSpgmr only: a preconditioner (both functions, or neither: none).
  KinsolPreconditioner preconditioner{};
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
  long jacobian_evaluations = 0;  // KINGetNumJacEvals (Newton on a matrix)
  long linear_iterations = 0;     // KINGetNumLinIters (Newton; SPGMR's Krylov iterations)
  // kSpgmr: KINGetNumLinFuncEvals (evaluations of F for difference-quotient J·v, KINSOL's
  // nfeSG, among `evaluations`), KINGetNumPrecEvals and KINGetNumPrecSolves (npe, nps),
  // KINGetNumLinConvFails (ncfl).
  long product_evaluations = 0;
  long preconditioner_setups = 0, preconditioner_solves = 0;
  long linear_convergence_failures = 0;
  bool budget_spent = false;  // an evaluation beyond max_evaluations was refused
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

  // For fixed-point strategies `function` is G; for Newton it is F and `jacobian` its dense
  // Jacobian (kDense; empty: KINSOL's difference quotients), `sparse` its sparse one (kKlu,
  // required). std::invalid_argument for options out of range or a malformed sparse pattern.
  KinsolSolver(int n, KinsolOptions options, Function function, Jacobian jacobian = {},
               KinsolSparseJacobian sparse = {});
  ~KinsolSolver();
  KinsolSolver(const KinsolSolver&) = delete;
  KinsolSolver& operator=(const KinsolSolver&) = delete;

  // x: initial guess in, KINSOL's answer out.
  KinsolResult solve(Eigen::VectorXd& x);

  static std::string name(KinsolStrategy strategy);
  // "kinsol:newton", "kinsol:newton-band", "kinsol:newton-klu", "kinsol:newton-spgmr".
  static std::string name(KinsolLinearSolver linear_solver);
  // The inverse of the names: "kinsol:fp", "kinsol:fp-aa2" and the four Newton names (each
  // kNewtonLineSearch); none for another.
  static std::optional<KinsolStrategy> strategy(const std::string& name);
  // The linear solver a Newton name runs; none for another name.
  static std::optional<KinsolLinearSolver> linear_solver(const std::string& name);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace nlobs::reference
