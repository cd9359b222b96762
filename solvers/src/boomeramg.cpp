// BoomerAMG through hypre's IJ interface on MPI_COMM_SELF (boomeramg.hpp).
#include "nlobs/solvers/linear/boomeramg.hpp"

#include <HYPRE.h>
#include <HYPRE_parcsr_ls.h>
#include <_hypre_parcsr_ls.h>  // hypre_ParAMGData's level count, a ParVector's local data
#include <mpi.h>

#include <cstdlib>
#include <limits>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

namespace nlobs {
namespace {

std::mutex& hypre_lock() {
  static std::mutex lock;
  return lock;
}

bool mpi_finalized() {
  int finalized = 0;
  return MPI_Finalized(&finalized) != MPI_SUCCESS || finalized != 0;
}

// At exit, when MPI was started here and nobody finalised it since (under the lock: not while
// another thread is inside hypre).
void finalize_mpi() {
  const std::lock_guard<std::mutex> guard(hypre_lock());
  if (!mpi_finalized()) (void)MPI_Finalize();
}

// MPI (a singleton process when the program did not start it) and hypre, once per process; then,
// at every call, whether hypre can run here now. Returns an empty string, or why not.
std::string hypre_ready() {
  static std::once_flag once;
  static std::string failure;
  std::call_once(once, [] {
    if (mpi_finalized()) return;  // reported below
    int up = 0;
    if (MPI_Initialized(&up) != MPI_SUCCESS) {
      failure = "boomeramg: MPI_Initialized failed";
      return;
    }
    if (!up) {
      // As reference/src/petsc_solver.cpp: no Open MPI signal handlers (a crash reports as it
      // would without MPI) and no daemon process. A user's setting of either wins.
      setenv("OMPI_MCA_opal_signal", "", 0);
      setenv("OMPI_MCA_ess_singleton_isolated", "1", 0);
      int provided = 0;
      if (MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided) != MPI_SUCCESS) {
        failure = "boomeramg: MPI did not start (MPI_Init_thread failed)";
        return;
      }
      std::atexit(finalize_mpi);
    }
    HYPRE_ClearAllErrors();  // hypre's error flag is one global, shared with PETSc's hypre
    if (HYPRE_Init() != 0) {
      failure = "boomeramg: HYPRE_Init failed";
      HYPRE_ClearAllErrors();
    }
  });
  if (!failure.empty()) return failure;
  if (mpi_finalized()) return "boomeramg: MPI has been finalised; hypre cannot run";
  int level = MPI_THREAD_SINGLE, main_thread = 0;
  MPI_Query_thread(&level);
  MPI_Is_thread_main(&main_thread);
  if (level < MPI_THREAD_SERIALIZED && !main_thread) {
    // A program's own MPI_Init (SINGLE) or PETSc's (FUNNELED): only the thread that started MPI
    // may call it.
    return "boomeramg: MPI was started at thread level " + std::to_string(level) +
           ", below MPI_THREAD_SERIALIZED, and this is not the thread that started it";
  }
  return {};
}

std::string describe_hypre_error(const char* call) {
  const HYPRE_Int code = HYPRE_GetError();
  char description[256] = {};
  HYPRE_DescribeError(code, description);
  HYPRE_ClearAllErrors();
  std::string text = description;
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return std::string("boomeramg: ") + call + " failed (hypre error " + std::to_string(code) + ": " +
         text + ")";
}

// The first row of a square, compressed J that has no stored entry on its diagonal (hypre takes
// a row's first entry as its diagonal when the diagonal is missing; an empty row takes a path of
// hypre 2.26's assembly that mislabels later rows' diagonals), or −1.
Index first_row_without_diagonal(const SparseJacobian& jac) {
  for (Index i = 0; i < jac.rows(); ++i) {
    bool found = false;
    for (SparseJacobian::InnerIterator it(jac, i); it && !found; ++it) found = it.col() == i;
    if (!found) return i;
  }
  return -1;
}

}  // namespace

bool boomeramg_available() {
  return true;
}

struct BoomerAmgPreconditioner::Impl {
  HYPRE_IJMatrix matrix = nullptr;
  HYPRE_IJVector rhs = nullptr, solution = nullptr;
  HYPRE_Solver solver = nullptr;
  HYPRE_Int n = 0;

  ~Impl() { release(); }
  void release() {
    // After MPI_Finalize hypre's objects are left to the process's end (hypre would call MPI).
    if (!mpi_finalized()) {
      if (solver) HYPRE_BoomerAMGDestroy(solver);
      if (matrix) HYPRE_IJMatrixDestroy(matrix);
      if (rhs) HYPRE_IJVectorDestroy(rhs);
      if (solution) HYPRE_IJVectorDestroy(solution);
    }
    solver = nullptr;
    matrix = nullptr;
    rhs = solution = nullptr;
    n = 0;
  }
  // The ParCSR objects behind the IJ ones, as BoomerAMG takes them.
  HYPRE_ParCSRMatrix par_matrix() const {
    void* object = nullptr;
    HYPRE_IJMatrixGetObject(matrix, &object);
    return static_cast<HYPRE_ParCSRMatrix>(object);
  }
  static HYPRE_ParVector par_vector(HYPRE_IJVector v) {
    void* object = nullptr;
    HYPRE_IJVectorGetObject(v, &object);
    return static_cast<HYPRE_ParVector>(object);
  }
  static double* data(HYPRE_IJVector v) {
    return hypre_VectorData(hypre_ParVectorLocalVector(par_vector(v)));
  }
};

BoomerAmgPreconditioner::BoomerAmgPreconditioner(BoomerAmgOptions options)
    : options_(options), impl_(std::make_unique<Impl>()) {
  options_.validate();
  (void)hypre_lock();  // constructed before this object: destroyed after it
}

BoomerAmgPreconditioner::~BoomerAmgPreconditioner() {
  const std::lock_guard<std::mutex> guard(hypre_lock());
  impl_.reset();
}

int BoomerAmgPreconditioner::levels() const {
  const std::lock_guard<std::mutex> guard(hypre_lock());
  if (!impl_->solver) return 0;
  return hypre_ParAMGDataNumLevels(reinterpret_cast<hypre_ParAMGData*>(impl_->solver));
}

LinearStatus BoomerAmgPreconditioner::setup(const SparseJacobian& jac) {
  const std::lock_guard<std::mutex> guard(hypre_lock());
  impl_->release();  // a failed setup leaves nothing to apply
  if (jac.rows() != jac.cols() || jac.rows() < 1) {
    message_ = "boomeramg: J is " + std::to_string(jac.rows()) + "x" + std::to_string(jac.cols()) +
               (jac.rows() < 1 ? ", empty" : ", not square");
    return LinearStatus::kInvalidInput;
  }
  if (const Index row = detail::first_non_finite_row(jac); row >= 0) {
    message_ = "boomeramg: J has a non-finite entry in row " + std::to_string(row);
    return LinearStatus::kNonFinite;
  }
  if (const Index row = first_row_without_diagonal(jac); row >= 0) {
    message_ = "boomeramg: J(" + std::to_string(row) + ", " + std::to_string(row) +
               ") is not stored: algebraic multigrid needs J's whole diagonal";
    return LinearStatus::kSingular;
  }
  if (const std::string failure = hypre_ready(); !failure.empty()) {
    message_ = failure;
    return LinearStatus::kPackageFailure;
  }
  HYPRE_ClearAllErrors();  // another user's (PETSc's hypre) would read as ours
  SparseJacobian compressed;
  const SparseJacobian* csr = &jac;
  if (!jac.isCompressed()) {
    compressed = jac;
    compressed.makeCompressed();
    csr = &compressed;
  }
  Impl& h = *impl_;
  const auto n = static_cast<HYPRE_Int>(csr->rows());
  std::vector<HYPRE_Int> rows(static_cast<std::size_t>(n)), row_lengths(rows.size());
  const int* start = csr->outerIndexPtr();
  for (HYPRE_Int i = 0; i < n; ++i) {
    rows[static_cast<std::size_t>(i)] = i;
    row_lengths[static_cast<std::size_t>(i)] = start[i + 1] - start[i];
  }
  // hypre's refusal of J in its setup (a zero diagonal entry, for one) is a singular J; a
  // failure to build its objects is hypre's own.
  const auto fail = [&](const char* call, LinearStatus status = LinearStatus::kPackageFailure) {
    message_ = describe_hypre_error(call);
    impl_->release();
    return status;
  };
  if (HYPRE_IJMatrixCreate(MPI_COMM_SELF, 0, n - 1, 0, n - 1, &h.matrix) != 0 ||
      HYPRE_IJMatrixSetObjectType(h.matrix, HYPRE_PARCSR) != 0 ||
      HYPRE_IJMatrixSetRowSizes(h.matrix, row_lengths.data()) != 0 ||
      HYPRE_IJMatrixInitialize(h.matrix) != 0 ||
      HYPRE_IJMatrixSetValues(h.matrix, n, row_lengths.data(), rows.data(), csr->innerIndexPtr(),
                              csr->valuePtr()) != 0 ||
      HYPRE_IJMatrixAssemble(h.matrix) != 0) {
    return fail("assembling J");
  }
  for (HYPRE_IJVector* v : {&h.rhs, &h.solution}) {
    if (HYPRE_IJVectorCreate(MPI_COMM_SELF, 0, n - 1, v) != 0 ||
        HYPRE_IJVectorSetObjectType(*v, HYPRE_PARCSR) != 0 || HYPRE_IJVectorInitialize(*v) != 0 ||
        HYPRE_IJVectorAssemble(*v) != 0) {
      return fail("creating a vector");
    }
  }
  h.n = n;
  if (HYPRE_BoomerAMGCreate(&h.solver) != 0) return fail("HYPRE_BoomerAMGCreate");
  // A preconditioner: a fixed number of cycles, no convergence test (tolerance 0), silent.
  HYPRE_BoomerAMGSetPrintLevel(h.solver, 0);
  HYPRE_BoomerAMGSetMaxIter(h.solver, options_.cycles);
  HYPRE_BoomerAMGSetTol(h.solver, 0.0);
  HYPRE_BoomerAMGSetStrongThreshold(h.solver, options_.strong_threshold);
  if (HYPRE_BoomerAMGSetup(h.solver, h.par_matrix(), h.par_vector(h.rhs),
                           h.par_vector(h.solution)) != 0) {
    return fail("HYPRE_BoomerAMGSetup", LinearStatus::kSingular);
  }
  message_.clear();
  return LinearStatus::kSolved;
}

void BoomerAmgPreconditioner::apply(const Vector<Dynamic>& r, Vector<Dynamic>& z) {
  const std::lock_guard<std::mutex> guard(hypre_lock());
  Impl& h = *impl_;
  z.resize(r.size());
  // The Krylov solvers set up before they apply; a wrong size is a caller's bug. NaN makes the
  // caller's check of M⁻¹ r name the failure instead of taking a plausible vector.
  const auto refuse = [&](std::string why) {
    message_ = std::move(why);
    z.setConstant(std::numeric_limits<double>::quiet_NaN());
  };
  if (!h.solver) return refuse("boomeramg: applied before a successful setup");
  if (r.size() != h.n) {
    return refuse("boomeramg: r has " + std::to_string(r.size()) + " entries, J " +
                  std::to_string(h.n) + " rows");
  }
  if (mpi_finalized()) return refuse("boomeramg: MPI has been finalised; hypre cannot run");
  double* b = Impl::data(h.rhs);
  double* x = Impl::data(h.solution);
  for (HYPRE_Int i = 0; i < h.n; ++i) {
    b[i] = r[i];
    x[i] = 0.0;
  }
  HYPRE_ClearAllErrors();
  const HYPRE_Int code =
      HYPRE_BoomerAMGSolve(h.solver, h.par_matrix(), h.par_vector(h.rhs), h.par_vector(h.solution));
  // Running out of cycles is what a preconditioner asks for (hypre flags it only with a
  // tolerance > 0); any other error leaves x meaningless.
  if ((code & ~HYPRE_ERROR_CONV) != 0) return refuse(describe_hypre_error("HYPRE_BoomerAMGSolve"));
  HYPRE_ClearAllErrors();
  for (HYPRE_Int i = 0; i < h.n; ++i) z[i] = x[i];
}

}  // namespace nlobs
