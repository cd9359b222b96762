#pragma once
// KINSOL (SUNDIALS) as a reference solver for the same problems our engines solve: fixed
// point, fixed point with Anderson acceleration, Newton with line search and a dense direct
// linear solver. KINSOL is set up once in the constructor and re-run by solve(), so a timing
// of solve() measures the iteration, not the set-up — the same treatment our engines get.
#include <Eigen/Core>
#include <functional>
#include <memory>
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
  long max_iterations = 10000;
};

struct KinsolResult {
  int flag = 0;           // KINSol's return flag
  std::string flag_name;  // KINGetReturnFlagName
  bool success = false;   // flag >= 0 (KIN_SUCCESS, KIN_INITIAL_GUESS_OK, KIN_STEP_LT_STPTOL)
  long iterations = 0;    // KINGetNumNonlinSolvIters
  long evaluations = 0;   // KINGetNumFuncEvals
  long jacobian_evaluations = 0;  // KINGetNumJacEvals (Newton only)
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

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace nlobs::reference
