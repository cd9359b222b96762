#include "nlobs/reference/kinsol_solver.hpp"

#include <kinsol/kinsol.h>
#include <kinsol/kinsol_ls.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_band.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunlinsol/sunlinsol_klu.h>
#include <sunlinsol/sunlinsol_spgmr.h>
#include <sunmatrix/sunmatrix_band.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <new>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace nlobs::reference {

struct KinsolSolver::Impl {
  int n = 0;
  KinsolOptions options;
  Function function;
  Jacobian jacobian;
  KinsolSparseJacobian sparse;
  SUNContext context = nullptr;
  void* kinsol = nullptr;
  N_Vector u = nullptr, u_scale = nullptr, f_scale = nullptr;
  SUNMatrix matrix = nullptr;
  SUNLinearSolver linear_solver = nullptr;
  Eigen::VectorXd x_in, f_out, f_in;
  Eigen::MatrixXd jac_out;  // kDense with a Jacobian only (n² doubles)
  long calls = 0;           // evaluations of F (or G), whoever asked
  long cap = 0;             // the evaluations KINSOL may make (0: any number)
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
  static int sparse_jacobian(N_Vector u_vec, N_Vector f_vec, SUNMatrix jac, void* data, N_Vector,
                             N_Vector) {
    auto* self = static_cast<Impl*>(data);
    self->x_in = Eigen::Map<const Eigen::VectorXd>(N_VGetArrayPointer(u_vec), self->n);
    self->f_in = Eigen::Map<const Eigen::VectorXd>(N_VGetArrayPointer(f_vec), self->n);
    // KINSOL zeroes the matrix before each call, its index arrays included: the pattern is
    // written every time.
    std::copy(self->sparse.row_starts.begin(), self->sparse.row_starts.end(),
              SUNSparseMatrix_IndexPointers(jac));
    std::copy(self->sparse.columns.begin(), self->sparse.columns.end(),
              SUNSparseMatrix_IndexValues(jac));
    try {
      self->sparse.values(self->x_in, self->f_in, SUNSparseMatrix_Data(jac));
    } catch (...) {
      return -1;
    }
    return 0;
  }
  static int preconditioner_setup(N_Vector u_vec, N_Vector u_scale_vec, N_Vector f_vec,
                                  N_Vector f_scale_vec, void* data) {
    auto* self = static_cast<Impl*>(data);
    const auto map = [n = self->n](N_Vector v) {
      return KinsolPreconditioner::ConstVector(N_VGetArrayPointer(v), n);
    };
    try {
      return self->options.preconditioner.setup(map(u_vec), map(u_scale_vec), map(f_vec),
                                                map(f_scale_vec));
    } catch (...) {
      return -1;
    }
  }
  static int preconditioner_solve(N_Vector u_vec, N_Vector u_scale_vec, N_Vector f_vec,
                                  N_Vector f_scale_vec, N_Vector v_vec, void* data) {
    auto* self = static_cast<Impl*>(data);
    const auto map = [n = self->n](N_Vector v) {
      return KinsolPreconditioner::ConstVector(N_VGetArrayPointer(v), n);
    };
    try {
      return self->options.preconditioner.solve(
          map(u_vec), map(u_scale_vec), map(f_vec), map(f_scale_vec),
          Eigen::Map<Eigen::VectorXd>(N_VGetArrayPointer(v_vec), self->n));
    } catch (...) {
      return -1;
    }
  }
  static void silent(int, const char*, const char*, char*, void*) {}

  // Frees what the constructor made, also when it threw half-way (a failed allocation).
  ~Impl() {
    if (kinsol) KINFree(&kinsol);
    if (linear_solver) SUNLinSolFree(linear_solver);
    if (matrix) SUNMatDestroy(matrix);
    for (N_Vector v : {u, u_scale, f_scale}) {
      if (v) N_VDestroy(v);
    }
    if (context) SUNContext_Free(&context);
  }

  // The linear solver and its matrix for options.linear_solver (Newton).
  void attach_linear_solver() {
    switch (options.linear_solver) {
      case KinsolLinearSolver::kDense:
        matrix = SUNDenseMatrix(n, n, context);
        break;
      case KinsolLinearSolver::kBand:
        // SUNDIALS 6: the band matrix keeps room for the LU's fill itself.
        matrix = SUNBandMatrix(n, options.upper_bandwidth, options.lower_bandwidth, context);
        break;
      case KinsolLinearSolver::kKlu:
        matrix = SUNSparseMatrix(n, n, static_cast<sunindextype>(sparse.columns.size()), CSR_MAT,
                                 context);
        break;
      case KinsolLinearSolver::kSpgmr:
        break;
    }
    // A matrix SUNDIALS could not allocate is null, and its linear solver would dereference it.
    if (options.linear_solver != KinsolLinearSolver::kSpgmr && matrix == nullptr) {
      throw std::bad_alloc();
    }
    switch (options.linear_solver) {
      case KinsolLinearSolver::kDense:
        linear_solver = SUNLinSol_Dense(u, matrix, context);
        break;
      case KinsolLinearSolver::kBand:
        linear_solver = SUNLinSol_Band(u, matrix, context);
        break;
      case KinsolLinearSolver::kKlu:
        linear_solver = SUNLinSol_KLU(u, matrix, context);
        break;
      case KinsolLinearSolver::kSpgmr:
        linear_solver = SUNLinSol_SPGMR(
            u, options.preconditioner.solve ? SUN_PREC_RIGHT : SUN_PREC_NONE, 15, context);
        if (linear_solver) check(SUNLinSol_SPGMRSetMaxRestarts(linear_solver, 2), "restarts");
        break;
    }
    if (linear_solver == nullptr) {
      throw std::runtime_error("KINSOL: creating the linear solver " +
                               KinsolSolver::name(options.linear_solver) + " failed");
    }
    check(KINSetLinearSolver(kinsol, linear_solver, matrix), "KINSetLinearSolver");
    if (options.linear_solver == KinsolLinearSolver::kDense && jacobian) {
      check(KINSetJacFn(kinsol, &Impl::dense_jacobian), "KINSetJacFn");
    }
    if (options.linear_solver == KinsolLinearSolver::kKlu) {
      check(KINSetJacFn(kinsol, &Impl::sparse_jacobian), "KINSetJacFn");
    }
    if (options.linear_solver == KinsolLinearSolver::kSpgmr && options.preconditioner.solve) {
      check(KINSetPreconditioner(kinsol, &Impl::preconditioner_setup, &Impl::preconditioner_solve),
            "KINSetPreconditioner");
    }
    check(KINSetMaxSetupCalls(kinsol, options.max_setup_calls), "KINSetMaxSetupCalls");
    check(KINSetMaxSubSetupCalls(kinsol, options.max_sub_setup_calls), "KINSetMaxSubSetupCalls");
  }

  void check(int flag, const char* call) {
    if (flag < 0) throw std::runtime_error(std::string("KINSOL: ") + call + " failed");
  }
};

namespace {

constexpr double kMaxBandEntries = 1.25e8;

// std::invalid_argument for a band or a sparse pattern that does not describe an n×n matrix.
void check_linear_solver_input(int n, const KinsolOptions& options,
                               const KinsolSparseJacobian& sparse) {
  if (options.strategy != KinsolStrategy::kNewtonLineSearch) return;
  const auto fail = [](const std::string& what) {
    throw std::invalid_argument("KinsolSolver: " + what);
  };
  if (options.max_setup_calls < 0) fail("max_setup_calls must be >= 0");
  if (options.max_sub_setup_calls < 0) fail("max_sub_setup_calls must be >= 0");
  if (options.linear_solver == KinsolLinearSolver::kBand) {
    for (const auto& [width, side] : {std::pair{options.lower_bandwidth, "lower"},
                                      std::pair{options.upper_bandwidth, "upper"}}) {
      if (width < 0 || width >= std::max(n, 1)) {
        fail(std::string(side) + " bandwidth " + std::to_string(width) + " is not in 0 .. " +
             std::to_string(n - 1));
      }
    }
    // SUNBandMatrix keeps n (2 lower + upper + 1) doubles (room for the LU's fill): a 2-D grid's
    // band of widths √n takes 24 GB at n = 10⁶.
    const double entries =
        static_cast<double>(n) *
        static_cast<double>(2 * options.lower_bandwidth + options.upper_bandwidth + 1);
    if (entries > kMaxBandEntries) {
      std::ostringstream os;
      os << "a band of widths " << options.lower_bandwidth << " (lower) and "
         << options.upper_bandwidth << " (upper) at n = " << n << " takes " << entries
         << " doubles, above the limit of " << kMaxBandEntries
         << " (1 GB); kinsol:newton-klu stores only the Jacobian's entries";
      fail(os.str());
    }
  }
  if (options.linear_solver != KinsolLinearSolver::kKlu) return;
  const auto& starts = sparse.row_starts;
  const auto& columns = sparse.columns;
  if (!sparse.values) fail("kinsol:newton-klu needs the sparse Jacobian's values function");
  if (starts.size() != static_cast<std::size_t>(n) + 1 || starts.front() != 0 ||
      starts.back() != static_cast<long>(columns.size())) {
    fail("the sparse Jacobian's row_starts must have n + 1 = " + std::to_string(n + 1) +
         " entries from 0 to the number of columns listed");
  }
  for (int i = 0; i < n; ++i) {
    if (starts[i + 1] < starts[i] || starts[i + 1] > starts.back()) {
      fail("row_starts is not non-decreasing at row " + std::to_string(i));
    }
    for (long k = starts[i]; k < starts[i + 1]; ++k) {
      if (columns[k] < 0 || columns[k] >= n || (k > starts[i] && columns[k] <= columns[k - 1])) {
        fail("row " + std::to_string(i) +
             " of the sparse Jacobian lists a column outside 0 .. n - 1 or out of order");
      }
    }
  }
}

}  // namespace

KinsolSolver::KinsolSolver(int n, KinsolOptions options, Function function, Jacobian jacobian,
                           KinsolSparseJacobian sparse)
    : impl_(std::make_unique<Impl>()) {
  check_linear_solver_input(n, options, sparse);
  if (!(options.max_newton_step >= 0.0 && std::isfinite(options.max_newton_step))) {
    throw std::invalid_argument("KinsolOptions::max_newton_step must be finite and >= 0");
  }
  if (options.max_evaluations != 0 && options.max_evaluations < 2) {
    throw std::invalid_argument("KinsolOptions::max_evaluations must be 0 (no limit) or >= 2");
  }
  if (options.max_iterations < 1) {
    throw std::invalid_argument("KinsolOptions::max_iterations must be >= 1");
  }
  if (!(options.step_tolerance >= 0.0 && std::isfinite(options.step_tolerance))) {
    throw std::invalid_argument("KinsolOptions::step_tolerance must be finite and >= 0");
  }
  const bool newton = options.strategy == KinsolStrategy::kNewtonLineSearch;
  if (!newton && !options.line_search) {
    throw std::invalid_argument("KinsolOptions::line_search = false is for Newton only");
  }
  if (options.constraints.size() != 0) {
    if (!newton || options.constraints.size() != n) {
      throw std::invalid_argument("KinsolOptions::constraints: for Newton, empty or of size n = " +
                                  std::to_string(n));
    }
    for (Eigen::Index i = 0; i < n; ++i) {
      const double c = options.constraints[i];
      if (c != 0.0 && c != 1.0 && c != 2.0 && c != -1.0 && c != -2.0) {
        throw std::invalid_argument("KinsolOptions::constraints[" + std::to_string(i) +
                                    "] is not one of 0, 1, 2, -1, -2");
      }
    }
  }
  if (static_cast<bool>(options.preconditioner.setup) !=
          static_cast<bool>(options.preconditioner.solve) ||
      (options.preconditioner.solve &&
       !(newton && options.linear_solver == KinsolLinearSolver::kSpgmr))) {
    throw std::invalid_argument(
        "KinsolOptions::preconditioner: both setup and solve, and only with kinsol:newton-spgmr");
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
  s.sparse = std::move(sparse);
  s.x_in.resize(n);
  s.f_out.resize(n);
  s.f_in.resize(n);  // the callbacks must not allocate outside their try
  if (options.strategy == KinsolStrategy::kNewtonLineSearch &&
      options.linear_solver == KinsolLinearSolver::kDense && s.jacobian) {
    s.jac_out.resize(n, n);
  }
  s.check(SUNContext_Create(nullptr, &s.context), "SUNContext_Create");
  s.u = N_VNew_Serial(n, s.context);
  s.u_scale = N_VNew_Serial(n, s.context);
  s.f_scale = N_VNew_Serial(n, s.context);
  if (!s.u || !s.u_scale || !s.f_scale) throw std::bad_alloc();
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
  s.check(KINSetScaledStepTol(
              s.kinsol, options.step_tolerance > 0.0 ? options.step_tolerance : options.tolerance),
          "KINSetScaledStepTol");
  if (options.constraints.size() == n) {
    N_Vector constraints = N_VNew_Serial(n, s.context);
    if (!constraints) throw std::bad_alloc();
    Eigen::Map<Eigen::VectorXd>(N_VGetArrayPointer(constraints), n) = options.constraints;
    const int flag = KINSetConstraints(s.kinsol, constraints);  // KINSOL keeps a copy
    N_VDestroy(constraints);
    s.check(flag, "KINSetConstraints");
  }
  s.check(KINSetNumMaxIters(s.kinsol, options.max_iterations), "KINSetNumMaxIters");
  if (options.strategy == KinsolStrategy::kNewtonLineSearch) s.attach_linear_solver();
}

KinsolSolver::~KinsolSolver() = default;

KinsolResult KinsolSolver::solve(Eigen::VectorXd& x) {
  Impl& s = *impl_;
  if (x.size() != s.n) throw std::invalid_argument("KinsolSolver::solve: wrong size");
  Eigen::Map<Eigen::VectorXd>(N_VGetArrayPointer(s.u), s.n) = x;
  const int strategy = s.options.strategy != KinsolStrategy::kNewtonLineSearch ? KIN_FP
                       : s.options.line_search                                 ? KIN_LINESEARCH
                                                                               : KIN_NONE;
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
  if (s.matrix) KINGetNumJacEvals(s.kinsol, &r.jacobian_evaluations);
  if (s.linear_solver) KINGetNumLinIters(s.kinsol, &r.linear_iterations);
  if (s.linear_solver && s.options.linear_solver == KinsolLinearSolver::kSpgmr) {
    KINGetNumLinFuncEvals(s.kinsol, &r.product_evaluations);
    KINGetNumPrecEvals(s.kinsol, &r.preconditioner_setups);
    KINGetNumPrecSolves(s.kinsol, &r.preconditioner_solves);
    KINGetNumLinConvFails(s.kinsol, &r.linear_convergence_failures);
  }
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
  for (KinsolStrategy s : {KinsolStrategy::kFixedPoint, KinsolStrategy::kFixedPointAnderson}) {
    if (KinsolSolver::name(s) == name) return s;
  }
  if (linear_solver(name)) return KinsolStrategy::kNewtonLineSearch;
  return std::nullopt;
}

std::optional<KinsolLinearSolver> KinsolSolver::linear_solver(const std::string& name) {
  for (KinsolLinearSolver l : {KinsolLinearSolver::kDense, KinsolLinearSolver::kBand,
                               KinsolLinearSolver::kKlu, KinsolLinearSolver::kSpgmr}) {
    if (KinsolSolver::name(l) == name) return l;
  }
  return std::nullopt;
}

std::string KinsolSolver::name(KinsolLinearSolver linear_solver) {
  switch (linear_solver) {
    case KinsolLinearSolver::kDense:
      return "kinsol:newton";
    case KinsolLinearSolver::kBand:
      return "kinsol:newton-band";
    case KinsolLinearSolver::kKlu:
      return "kinsol:newton-klu";
    case KinsolLinearSolver::kSpgmr:
      return "kinsol:newton-spgmr";
  }
  return "kinsol:?";
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
