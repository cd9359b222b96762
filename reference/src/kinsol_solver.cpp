#include "nlobs/reference/kinsol_solver.hpp"

#include <kinsol/kinsol.h>
#include <kinsol/kinsol_ls.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace nlobs::reference {

struct KinsolSolver::Impl {
  int n = 0;
  KinsolOptions options;
  Function function;
  Jacobian jacobian;
  SUNContext context = nullptr;
  void* kinsol = nullptr;
  N_Vector u = nullptr, u_scale = nullptr, f_scale = nullptr;
  SUNMatrix matrix = nullptr;
  SUNLinearSolver linear_solver = nullptr;
  Eigen::VectorXd x_in, f_out;
  Eigen::MatrixXd jac_out;
  long calls = 0;  // evaluations of F (or G), whoever asked
  long cap = 0;    // the evaluations KINSOL may make (0: any number)
  bool refused = false;

  static int residual(N_Vector u_vec, N_Vector f_vec, void* data) {
    auto* self = static_cast<Impl*>(data);
    if (self->cap > 0 && self->calls >= self->cap) {
      self->refused = true;
      return -1;  // < 0: unrecoverable, KINSOL stops
    }
    self->x_in = Eigen::Map<const Eigen::VectorXd>(N_VGetArrayPointer(u_vec), self->n);
    ++self->calls;
    try {  // no exception may unwind through KINSOL
      self->function(self->x_in, self->f_out);
    } catch (...) {
      return -1;
    }
    Eigen::Map<Eigen::VectorXd>(N_VGetArrayPointer(f_vec), self->n) = self->f_out;
    return self->f_out.allFinite() ? 0 : 1;  // > 0: recoverable error
  }
  static int dense_jacobian(N_Vector u_vec, N_Vector, SUNMatrix jac, void* data, N_Vector,
                            N_Vector) {
    auto* self = static_cast<Impl*>(data);
    self->x_in = Eigen::Map<const Eigen::VectorXd>(N_VGetArrayPointer(u_vec), self->n);
    try {
      self->jacobian(self->x_in, self->jac_out);
    } catch (...) {
      return -1;
    }
    // SUNDIALS dense matrices are column-major, like Eigen's default.
    Eigen::Map<Eigen::MatrixXd>(SUNDenseMatrix_Data(jac), self->n, self->n) = self->jac_out;
    return 0;
  }
  static void silent(int, const char*, const char*, char*, void*) {}

  void check(int flag, const char* call) {
    if (flag < 0) throw std::runtime_error(std::string("KINSOL: ") + call + " failed");
  }
};

KinsolSolver::KinsolSolver(int n, KinsolOptions options, Function function, Jacobian jacobian)
    : impl_(std::make_unique<Impl>()) {
  if (!(options.max_newton_step >= 0.0 && std::isfinite(options.max_newton_step))) {
    throw std::invalid_argument("KinsolOptions::max_newton_step must be finite and >= 0");
  }
  if (options.max_evaluations != 0 && options.max_evaluations < 2) {
    throw std::invalid_argument("KinsolOptions::max_evaluations must be 0 (no limit) or >= 2");
  }
  if (options.max_iterations < 1) {
    throw std::invalid_argument("KinsolOptions::max_iterations must be >= 1");
  }
  for (const auto& [scale, name] :
       {std::pair{&options.u_scale, "u_scale"}, std::pair{&options.f_scale, "f_scale"}}) {
    if (scale->size() != 0 && scale->size() != n) {
      throw std::invalid_argument(std::string("KinsolOptions::") + name + " has size " +
                                  std::to_string(scale->size()) + " for n = " + std::to_string(n));
    }
    if (!((scale->array() > 0.0).all() && scale->allFinite())) {
      throw std::invalid_argument(std::string("KinsolOptions::") + name +
                                  ": every entry must be finite and > 0");
    }
  }
  Impl& s = *impl_;
  s.n = n;
  s.options = options;
  s.cap = options.max_evaluations > 0 ? options.max_evaluations - 1 : 0;
  s.function = std::move(function);
  s.jacobian = std::move(jacobian);
  s.x_in.resize(n);
  s.f_out.resize(n);
  s.jac_out.resize(n, n);
  s.check(SUNContext_Create(nullptr, &s.context), "SUNContext_Create");
  s.u = N_VNew_Serial(n, s.context);
  s.u_scale = N_VNew_Serial(n, s.context);
  s.f_scale = N_VNew_Serial(n, s.context);
  for (auto [vector, scale] :
       {std::pair{s.u_scale, &options.u_scale}, std::pair{s.f_scale, &options.f_scale}}) {
    if (scale->size() == n) {
      Eigen::Map<Eigen::VectorXd>(N_VGetArrayPointer(vector), n) = *scale;
    } else {
      N_VConst(1.0, vector);
    }
  }
  s.kinsol = KINCreate(s.context);
  if (s.kinsol == nullptr) throw std::runtime_error("KINSOL: KINCreate failed");
  s.check(KINSetErrHandlerFn(s.kinsol, &Impl::silent, nullptr), "KINSetErrHandlerFn");
  if (options.strategy == KinsolStrategy::kFixedPointAnderson) {
    s.check(KINSetMAA(s.kinsol, options.anderson_depth), "KINSetMAA");  // before KINInit
  }
  N_VConst(0.0, s.u);
  s.check(KINInit(s.kinsol, &Impl::residual, s.u), "KINInit");
  s.check(KINSetUserData(s.kinsol, &s), "KINSetUserData");
  s.check(KINSetFuncNormTol(s.kinsol, options.tolerance), "KINSetFuncNormTol");
  s.check(KINSetScaledStepTol(s.kinsol, options.tolerance), "KINSetScaledStepTol");
  s.check(KINSetNumMaxIters(s.kinsol, options.max_iterations), "KINSetNumMaxIters");
  if (options.strategy == KinsolStrategy::kNewtonLineSearch) {
    s.matrix = SUNDenseMatrix(n, n, s.context);
    s.linear_solver = SUNLinSol_Dense(s.u, s.matrix, s.context);
    s.check(KINSetLinearSolver(s.kinsol, s.linear_solver, s.matrix), "KINSetLinearSolver");
    if (s.jacobian) s.check(KINSetJacFn(s.kinsol, &Impl::dense_jacobian), "KINSetJacFn");
    s.check(KINSetMaxSetupCalls(s.kinsol, 1), "KINSetMaxSetupCalls");  // exact Newton
  }
}

KinsolSolver::~KinsolSolver() {
  Impl& s = *impl_;
  KINFree(&s.kinsol);
  if (s.linear_solver) SUNLinSolFree(s.linear_solver);
  if (s.matrix) SUNMatDestroy(s.matrix);
  N_VDestroy(s.u);
  N_VDestroy(s.u_scale);
  N_VDestroy(s.f_scale);
  SUNContext_Free(&s.context);
}

KinsolResult KinsolSolver::solve(Eigen::VectorXd& x) {
  Impl& s = *impl_;
  if (x.size() != s.n) throw std::invalid_argument("KinsolSolver::solve: wrong size");
  Eigen::Map<Eigen::VectorXd>(N_VGetArrayPointer(s.u), s.n) = x;
  const int strategy =
      s.options.strategy == KinsolStrategy::kNewtonLineSearch ? KIN_LINESEARCH : KIN_FP;
  if (s.options.strategy == KinsolStrategy::kNewtonLineSearch) {
    s.check(KINSetMaxNewtonStep(s.kinsol, s.options.max_newton_step), "KINSetMaxNewtonStep");
  }
  KinsolResult r;
  s.calls = 0;
  s.refused = false;
  r.flag = KINSol(s.kinsol, s.u, strategy, s.u_scale, s.f_scale);
  char* name = KINGetReturnFlagName(r.flag);
  r.flag_name = name ? name : "?";
  free(name);
  KINGetNumNonlinSolvIters(s.kinsol, &r.iterations);
  if (s.linear_solver) KINGetNumJacEvals(s.kinsol, &r.jacobian_evaluations);
  x = Eigen::Map<const Eigen::VectorXd>(N_VGetArrayPointer(s.u), s.n);
  // Judge the returned point ourselves (one more evaluation, counted).
  r.residual = std::numeric_limits<double>::infinity();
  if (x.allFinite()) {
    ++s.calls;
    s.function(x, s.f_out);
    const bool fixed_point = s.options.strategy != KinsolStrategy::kNewtonLineSearch;
    if (s.f_out.allFinite()) {
      Eigen::VectorXd f = fixed_point ? Eigen::VectorXd(s.f_out - x) : s.f_out;
      if (s.options.f_scale.size() == s.n) f.array() *= s.options.f_scale.array();
      r.residual = f.lpNorm<Eigen::Infinity>();
    }
  }
  r.evaluations = s.calls;
  r.budget_spent = s.refused;
  r.success = r.flag >= 0 && r.residual <= s.options.tolerance;
  if (r.flag >= 0 && !r.success) {
    std::ostringstream os;
    if (!x.allFinite()) {
      os << "returned a point that is not finite";
    } else {
      os << (s.options.f_scale.size() ? "|D_f F| " : "|F| ") << r.residual << " > tolerance "
         << s.options.tolerance;
    }
    r.reason = os.str();
  }
  return r;
}

std::string KinsolResult::status() const {
  if (success) return "converged";
  if (budget_spent) return "max_evaluations";
  if (flag >= 0) return std::isfinite(residual) ? "residual_above_tolerance" : "non_finite";
  switch (flag) {
    case KIN_MAXITER_REACHED:
      return "max_iterations";
    case KIN_FIRST_SYSFUNC_ERR:
    case KIN_REPTD_SYSFUNC_ERR:
      return "non_finite";
    default:
      break;
  }
  // KINGetReturnFlagName says "NONE" for flags it does not know (KIN_VECTOROP_ERR,
  // KIN_CONTEXT_ERR in SUNDIALS 6.4): the number then.
  std::string name = flag_name;
  if (name.rfind("KIN_", 0) != 0) name = "kin_flag_" + std::to_string(flag);
  for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return name;
}

std::optional<KinsolStrategy> KinsolSolver::strategy(const std::string& name) {
  for (KinsolStrategy s : {KinsolStrategy::kFixedPoint, KinsolStrategy::kFixedPointAnderson,
                           KinsolStrategy::kNewtonLineSearch}) {
    if (KinsolSolver::name(s) == name) return s;
  }
  return std::nullopt;
}

std::string KinsolSolver::name(KinsolStrategy strategy) {
  switch (strategy) {
    case KinsolStrategy::kFixedPoint:
      return "kinsol:fp";
    case KinsolStrategy::kFixedPointAnderson:
      return "kinsol:fp-aa2";
    case KinsolStrategy::kNewtonLineSearch:
      return "kinsol:newton";
  }
  return "kinsol:?";
}

}  // namespace nlobs::reference
