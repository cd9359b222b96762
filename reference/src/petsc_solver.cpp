// PETSc SNES on one process: see petsc_solver.hpp. Every PETSc call goes through check(), with
// an error handler that records PETSc's message instead of printing a traceback, pushed for the
// duration of each of our calls (a program that uses PETSc itself keeps its own handler).
#include "nlobs/reference/petsc_solver.hpp"

#include <petscsnes.h>

#include <algorithm>
#include <cctype>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <iomanip>
#include <limits>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <string>

#include "petsc_option_rules.hpp"

namespace nlobs::reference {

using petsc_rules::lower_word;
using petsc_rules::names_a_viewer;
using petsc_rules::validate_option;

namespace {

// The first message of the error being handled (PETSC_ERROR_INITIAL), for the exception we throw.
thread_local std::string g_petsc_message;

PetscErrorCode record_error(MPI_Comm, int, const char* function, const char*, PetscErrorCode code,
                            PetscErrorType type, const char* message, void*) {
  if (type == PETSC_ERROR_INITIAL) {
    g_petsc_message =
        std::string(message ? message : "") + " (in " + (function ? function : "?") + ")";
  }
  return code;
}

// Our handler while it lives.
class QuietErrors {
 public:
  QuietErrors() {
    g_petsc_message.clear();
    pushed_ = PetscPushErrorHandler(record_error, nullptr) == 0;
  }
  ~QuietErrors() {
    if (pushed_) (void)PetscPopErrorHandler();
  }
  QuietErrors(const QuietErrors&) = delete;
  QuietErrors& operator=(const QuietErrors&) = delete;

 private:
  bool pushed_ = false;
};

std::string petsc_message(PetscErrorCode code) {
  if (!g_petsc_message.empty()) return g_petsc_message;
  const char* text = nullptr;
  (void)PetscErrorMessage(code, &text, nullptr);
  return text ? text : "PETSc error " + std::to_string(code);
}

void check(PetscErrorCode code, const char* what) {
  if (code != 0)
    throw std::invalid_argument(std::string("PETSc: ") + what + ": " + petsc_message(code));
}

// Options PETSc reads only during a solve (the printing viewers petsc_option_rules.hpp takes),
// which SNESSetFromOptions leaves unread. `name` is without the leading '-'.
bool read_while_solving(const std::string& name) {
  return names_a_viewer("-" + name);
}

// At exit, unless the program finalised MPI first (it owns MPI then: PETSc cannot finalise after
// it).
void finalize_petsc() {
  int mpi_finalized = 0;
  if (MPI_Finalized(&mpi_finalized) != MPI_SUCCESS || mpi_finalized) return;
  PetscBool finalized = PETSC_FALSE;
  if (PetscFinalized(&finalized) == 0 && !finalized) (void)PetscFinalize();
}

bool petsc_finalized() {
  PetscBool finalized = PETSC_FALSE;
  return PetscFinalized(&finalized) != 0 || finalized;
}

std::string format_double(double v) {
  std::ostringstream os;
  os << std::setprecision(3) << v;
  return os.str();
}

}  // namespace

bool petsc_available() {
  return true;
}

void initialize_petsc() {
  static std::once_flag once;
  static std::string failure;
  std::call_once(once, [] {
    PetscBool up = PETSC_FALSE;
    if (PetscInitialized(&up) == 0 && up) return;  // the program's own PETSc
    int mpi_up = 0;
    if (MPI_Initialized(&mpi_up) == MPI_SUCCESS && !mpi_up) {
      // MPI starts here, as a singleton process: without Open MPI's signal handlers (a crash
      // reports as it would without MPI, through the sanitizers' or the shell's) and without
      // its daemon process. A user's setting of either wins (no overwrite).
      setenv("OMPI_MCA_opal_signal", "", 0);
      setenv("OMPI_MCA_ess_singleton_isolated", "1", 0);
    }
    // No signal handlers of PETSc's either, no ~/.petscrc.
    static char arg0[] = "nlobs", arg1[] = "-no_signal_handler", arg2[] = "-skip_petscrc";
    static char* args[] = {arg0, arg1, arg2, nullptr};
    int argc = 3;
    char** argv = args;
    if (PetscInitialize(&argc, &argv, nullptr, nullptr) != 0) {
      failure = "PETSc did not start (PetscInitialize failed)";
      return;
    }
    // PETSC_OPTIONS as PETSc read it at its start: not for our solvers, whose options are their
    // names' (a reproducible row); what PETSc makes itself during a solve (the colouring) would
    // otherwise read it.
    (void)PetscOptionsClear(nullptr);
    std::atexit(finalize_petsc);
  });
  if (!failure.empty()) throw std::runtime_error(failure);
}

struct PetscSnesSolver::Impl {
  int n = 0;
  PetscSnesOptions options;
  Function function;
  double check_tolerance = 1e-8;
  std::vector<PetscInt> starts, columns;  // the Jacobian's pattern, the diagonal included
  SNES snes = nullptr;
  Vec x = nullptr, r = nullptr;
  Mat jacobian_matrix = nullptr;
  PetscOptions database = nullptr;
  bool stale = false;  // the last solve ended in an error: PETSc's objects are made anew
  Eigen::VectorXd x_in, f_out;
  long calls = 0, jacobians = 0;
  long cap = 0;  // the evaluations SNES may make (0: any number)
  bool refused = false;
  std::string callback_error;  // why the callback returned an error, if it says
  std::exception_ptr thrown;

  static PetscErrorCode residual(SNES, Vec x_vec, Vec f_vec, void* data) {
    auto* self = static_cast<Impl*>(data);
    if (self->cap > 0 && self->calls >= self->cap) {
      self->refused = true;
      self->callback_error =
          "the evaluation budget is spent (" + std::to_string(self->options.max_evaluations) + ")";
      return PETSC_ERR_USER;  // SNESSolve returns it: the run stops
    }
    const PetscScalar* xa = nullptr;
    if (VecGetArrayRead(x_vec, &xa) != 0) return PETSC_ERR_LIB;
    self->x_in = Eigen::Map<const Eigen::VectorXd>(xa, self->n);
    if (VecRestoreArrayRead(x_vec, &xa) != 0) return PETSC_ERR_LIB;
    ++self->calls;
    try {  // no exception may unwind through PETSc
      self->function(self->x_in, self->f_out);
    } catch (...) {
      self->thrown = std::current_exception();
      return PETSC_ERR_USER;
    }
    if (self->f_out.size() != self->n) {
      self->callback_error = "F returned " + std::to_string(self->f_out.size()) +
                             " values, not n = " + std::to_string(self->n);
      return PETSC_ERR_USER;
    }
    PetscScalar* fa = nullptr;
    if (VecGetArray(f_vec, &fa) != 0) return PETSC_ERR_LIB;
    Eigen::Map<Eigen::VectorXd>(fa, self->n) = self->f_out;
    return VecRestoreArray(f_vec, &fa);  // NaN or inf: SNES's own test (DIVERGED_FNORM_NAN)
  }

  // PETSc's coloured differences, counted: with no colouring given, PETSc colours the matrix's
  // nonzero structure itself (distance 2, smallest-last) and keeps the colouring on the matrix.
  static PetscErrorCode jacobian(SNES s, Vec x_vec, Mat j, Mat p, void* data) {
    ++static_cast<Impl*>(data)->jacobians;
    return SNESComputeJacobianDefaultColor(s, x_vec, j, p, nullptr);
  }

  // Makes the vectors, the Jacobian's matrix (F's pattern, zeros until PETSc's differences fill
  // it), the private options database and the SNES; refuses an option SNESSetFromOptions did not
  // read.
  void build() {
    check(VecCreateSeq(PETSC_COMM_SELF, n, &x), "VecCreateSeq");
    check(VecDuplicate(x, &r), "VecDuplicate");
    check(MatCreate(PETSC_COMM_SELF, &jacobian_matrix), "MatCreate");
    check(MatSetSizes(jacobian_matrix, n, n, n, n), "MatSetSizes");
    check(MatSetType(jacobian_matrix, MATSEQAIJ), "MatSetType");
    check(MatSeqAIJSetPreallocationCSR(jacobian_matrix, starts.data(), columns.data(), nullptr),
          "MatSeqAIJSetPreallocationCSR");

    check(PetscOptionsCreate(&database), "PetscOptionsCreate");
    for (const auto& [key, value] : options.options) {
      check(PetscOptionsSetValue(database, key.c_str(), value.empty() ? nullptr : value.c_str()),
            key.c_str());
    }
    check(SNESCreate(PETSC_COMM_SELF, &snes), "SNESCreate");
    check(PetscObjectSetOptions(reinterpret_cast<PetscObject>(snes), database),
          "PetscObjectSetOptions");
    check(SNESSetType(snes, options.type.c_str()), ("SNES type '" + options.type + "'").c_str());
    // The line search is made by the type without the SNES's database: give it ours (the KSP
    // and PC take it from the SNES).
    SNESLineSearch line_search = nullptr;
    check(SNESGetLineSearch(snes, &line_search), "SNESGetLineSearch");
    check(PetscObjectSetOptions(reinterpret_cast<PetscObject>(line_search), database),
          "PetscObjectSetOptions");
    check(SNESSetFunction(snes, r, Impl::residual, this), "SNESSetFunction");
    check(SNESSetJacobian(snes, jacobian_matrix, jacobian_matrix, Impl::jacobian, this),
          "SNESSetJacobian");
    // PETSc's own count of F (its differences excluded) is not what bounds the run: ours is.
    check(SNESSetTolerances(snes, options.absolute_tolerance, options.relative_tolerance,
                            options.step_tolerance, static_cast<PetscInt>(options.max_iterations),
                            std::numeric_limits<PetscInt>::max()),
          "SNESSetTolerances");
    check(SNESSetFromOptions(snes), "SNESSetFromOptions");
    // SNESSetFromOptions reads the SNES's, its line search's, KSP's and PC's options: one left
    // unread is a misspelling or one of another type's.
    PetscInt left = 0;
    char** names = nullptr;
    char** values = nullptr;
    check(PetscOptionsLeftGet(database, &left, &names, &values), "PetscOptionsLeftGet");
    std::string unused;
    for (PetscInt i = 0; i < left; ++i) {
      if (!read_while_solving(names[i])) {
        unused += std::string(unused.empty() ? "" : ", ") + "-" + names[i];
      }
    }
    check(PetscOptionsLeftRestore(database, &left, &names, &values), "PetscOptionsLeftRestore");
    if (!unused.empty()) {
      throw std::invalid_argument("PETSc SNES " + options.type + " did not use the option(s) " +
                                  unused + " (misspelt, or of another type)");
    }
  }

  // After PETSc's finalisation (a solver that outlives it) nothing may be destroyed: left.
  void release() {
    if (petsc_finalized()) return;
    if (snes) (void)SNESDestroy(&snes);
    if (jacobian_matrix) (void)MatDestroy(&jacobian_matrix);
    if (x) (void)VecDestroy(&x);
    if (r) (void)VecDestroy(&r);
    if (database) (void)PetscOptionsDestroy(&database);
    snes = nullptr;
    jacobian_matrix = nullptr;
    x = r = nullptr;
    database = nullptr;
  }

  ~Impl() { release(); }
};

namespace {

void validate(int n, const PetscSnesOptions& o, const PetscPattern& pattern,
              double check_tolerance) {
  const auto fail = [](const std::string& what) {
    throw std::invalid_argument("PETSc SNES: " + what);
  };
  if (n < 1) fail("n = " + std::to_string(n) + " must be at least 1");
  for (double t : {o.absolute_tolerance, o.relative_tolerance, o.step_tolerance}) {
    if (!(t >= 0.0) || !std::isfinite(t)) fail("tolerances must be finite and >= 0");
  }
  if (o.max_iterations < 1 || o.max_iterations > INT_MAX) {
    fail("max_iterations = " + std::to_string(o.max_iterations) + " must be in 1 .. " +
         std::to_string(INT_MAX));
  }
  if (o.max_evaluations < 0 || o.max_evaluations == 1) {
    fail("max_evaluations = " + std::to_string(o.max_evaluations) +
         " must be 0 (no limit) or at least 2");
  }
  if (!(check_tolerance > 0.0) || !std::isfinite(check_tolerance)) {
    fail("check_tolerance must be finite and > 0");
  }
  if (o.type.empty() || !lower_word(o.type, 0)) {
    fail("type '" + o.type + "' is not a SNES type name (lower-case letters and digits)");
  }
  for (const auto& [key, value] : o.options) validate_option(key, value);
  if (pattern.row_starts.empty()) {
    if (!pattern.columns.empty()) fail("pattern: columns without row_starts");
    if (n > 2000) fail("no pattern at n = " + std::to_string(n) + ": a dense one is for n <= 2000");
    return;
  }
  if (pattern.row_starts.size() != static_cast<std::size_t>(n) + 1 || pattern.row_starts[0] != 0 ||
      pattern.row_starts.back() != static_cast<long>(pattern.columns.size())) {
    fail("pattern: row_starts must have n + 1 entries from 0 to the number of columns");
  }
  // n more for the diagonal, which the pattern may leave out.
  if (pattern.columns.size() + static_cast<std::size_t>(n) >
      static_cast<std::size_t>(std::numeric_limits<PetscInt>::max())) {
    fail("pattern: more nonzeros than PETSc's 32-bit indices hold");
  }
  for (int i = 0; i < n; ++i) {
    const long b = pattern.row_starts[static_cast<std::size_t>(i)];
    const long e = pattern.row_starts[static_cast<std::size_t>(i) + 1];
    if (e < b) fail("pattern: row_starts decrease at row " + std::to_string(i));
    for (long k = b; k < e; ++k) {
      const long c = pattern.columns[static_cast<std::size_t>(k)];
      if (c < 0 || c >= n || (k > b && c <= pattern.columns[static_cast<std::size_t>(k) - 1])) {
        fail("pattern: row " + std::to_string(i) +
             " has a column out of range or out of increasing order");
      }
    }
  }
}

}  // namespace

PetscSnesSolver::PetscSnesSolver(int n, PetscSnesOptions options, Function function,
                                 PetscPattern pattern, double check_tolerance)
    : impl_(std::make_unique<Impl>()) {
  validate(n, options, pattern, check_tolerance);
  if (!function) throw std::invalid_argument("PETSc SNES: no function F");
  initialize_petsc();
  QuietErrors quiet;
  Impl& s = *impl_;
  s.n = n;
  s.options = std::move(options);
  s.function = std::move(function);
  s.check_tolerance = check_tolerance;
  s.x_in.resize(n);
  s.f_out.resize(n);
  // F's pattern with the diagonal (ILU(0), PETSc's default, needs it in the structure).
  s.starts.reserve(static_cast<std::size_t>(n) + 1);
  s.starts.push_back(0);
  for (int i = 0; i < n; ++i) {
    const auto row = static_cast<std::size_t>(i);
    const long b = pattern.row_starts.empty() ? 0 : pattern.row_starts[row];
    const long e = pattern.row_starts.empty() ? n : pattern.row_starts[row + 1];
    bool diagonal = false;
    for (long k = b; k < e; ++k) {
      const long c = pattern.row_starts.empty() ? k : pattern.columns[static_cast<std::size_t>(k)];
      if (!diagonal && c > i) {
        s.columns.push_back(i);
        diagonal = true;
      }
      diagonal = diagonal || c == i;
      s.columns.push_back(static_cast<PetscInt>(c));
    }
    if (!diagonal) s.columns.push_back(i);
    s.starts.push_back(static_cast<PetscInt>(s.columns.size()));
  }
  s.build();
}

PetscSnesSolver::~PetscSnesSolver() {
  if (impl_) {
    QuietErrors quiet;
    impl_.reset();
  }
}

PetscSnesResult PetscSnesSolver::solve(Eigen::VectorXd& x) {
  Impl& s = *impl_;
  if (x.size() != s.n) {
    throw std::invalid_argument("PETSc SNES: x has size " + std::to_string(x.size()) +
                                ", not n = " + std::to_string(s.n));
  }
  if (petsc_finalized()) throw std::runtime_error("PETSc SNES: PETSc has been finalised");
  QuietErrors quiet;
  if (s.stale) {  // an error leaves PETSc's work vectors in a state SNES does not undo
    s.release();
    s.build();
    s.stale = false;
  }
  PetscSnesResult out;
  s.calls = s.jacobians = 0;
  s.refused = false;
  s.callback_error.clear();
  s.thrown = nullptr;
  // One evaluation is kept for the check of the answer.
  s.cap = s.options.max_evaluations > 0 ? s.options.max_evaluations - 1 : 0;
  PetscScalar* xa = nullptr;
  check(VecGetArray(s.x, &xa), "VecGetArray");
  Eigen::Map<Eigen::VectorXd>(xa, s.n) = x;
  check(VecRestoreArray(s.x, &xa), "VecRestoreArray");

  const PetscErrorCode code = SNESSolve(s.snes, nullptr, s.x);
  if (code != 0) s.stale = true;
  if (s.thrown) std::rethrow_exception(s.thrown);
  if (code != 0) {
    out.error = s.callback_error.empty() ? petsc_message(code) : s.callback_error;
  } else {
    SNESConvergedReason reason = SNES_CONVERGED_ITERATING;
    check(SNESGetConvergedReason(s.snes, &reason), "SNESGetConvergedReason");
    out.reason = static_cast<int>(reason);
    out.reason_name = SNESConvergedReasons[reason];
  }
  PetscInt its = 0, lits = 0;
  (void)SNESGetIterationNumber(s.snes, &its);
  (void)SNESGetLinearSolveIterations(s.snes, &lits);
  out.iterations = its;
  out.linear_iterations = lits;
  out.budget_spent = s.refused;
  const PetscScalar* xr = nullptr;
  check(VecGetArrayRead(s.x, &xr), "VecGetArrayRead");
  x = Eigen::Map<const Eigen::VectorXd>(xr, s.n);
  check(VecRestoreArrayRead(s.x, &xr), "VecRestoreArrayRead");

  // The check, as the KINSOL adapter's: PETSc's step test (and a type's own) stop on the step.
  if (!x.allFinite()) {
    out.residual = std::numeric_limits<double>::infinity();
    out.reason_text = "returned a point that is not finite";
  } else {
    ++s.calls;
    s.function(x, s.f_out);
    out.residual = s.f_out.allFinite() ? s.f_out.lpNorm<Eigen::Infinity>()
                                       : std::numeric_limits<double>::infinity();
    if (!s.f_out.allFinite()) {
      out.reason_text = "returned a point where F is not finite";
    } else if (!(out.residual <= s.check_tolerance)) {
      out.reason_text = "|F|inf " + format_double(out.residual) + " > tolerance " +
                        format_double(s.check_tolerance);
    }
  }
  out.success = out.reason > 0 && out.reason_text.empty() && !out.budget_spent;
  out.evaluations = s.calls;
  out.jacobian_evaluations = s.jacobians;
  return out;
}

}  // namespace nlobs::reference
