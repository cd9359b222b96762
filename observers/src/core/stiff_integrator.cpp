#include "nlobs/observers/core/stiff_integrator.hpp"

#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <algorithm>
#include <cstdlib>
#include <sstream>
#include <vector>

#include "nlobs/solvers/status.hpp"

namespace nlobs {

struct StiffIntegrator::Impl {
  int size = 0;
  Rhs rhs;
  Jacobian jacobian;
  SUNContext context = nullptr;
  N_Vector y = nullptr;
  SUNMatrix matrix = nullptr;
  SUNLinearSolver solver = nullptr;
  void* cvode = nullptr;
  std::vector<double> backup;
  long steps = 0;
  bool initialised = false;

  static int f(sunrealtype t, N_Vector y, N_Vector ydot, void* user) {
    auto* self = static_cast<Impl*>(user);
    return self->rhs(t, N_VGetArrayPointer(y), N_VGetArrayPointer(ydot)) ? 0 : 1;  // 1: recoverable
  }
  static int jac(sunrealtype t, N_Vector y, N_Vector, SUNMatrix J, void* user, N_Vector, N_Vector,
                 N_Vector) {
    auto* self = static_cast<Impl*>(user);
    self->jacobian(t, N_VGetArrayPointer(y), SUNDenseMatrix_Data(J));  // column-major
    return 0;
  }
  ~Impl() {
    if (cvode) CVodeFree(&cvode);
    if (solver) SUNLinSolFree(solver);
    if (matrix) SUNMatDestroy(matrix);
    if (y) N_VDestroy(y);
    if (context) SUNContext_Free(&context);
  }
};

StiffIntegrator::StiffIntegrator(int size, Rhs rhs, Jacobian jacobian, double relative_tolerance,
                                 double absolute_tolerance)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  if (size < 1 || !rhs || !(relative_tolerance > 0.0) || !(absolute_tolerance > 0.0)) {
    throw InvalidInput("StiffIntegrator: size >= 1, F and tolerances > 0 required");
  }
  s.size = size;
  s.rhs = std::move(rhs);
  s.jacobian = std::move(jacobian);
  s.backup.resize(static_cast<size_t>(size));
  const auto check = [](bool ok, const char* what) {
    if (!ok) throw std::runtime_error(std::string("CVODE set-up failed: ") + what);
  };
  check(SUNContext_Create(nullptr, &s.context) == 0, "SUNContext_Create");
  s.y = N_VNew_Serial(size, s.context);
  check(s.y != nullptr, "N_VNew_Serial");
  N_VConst(0.0, s.y);
  s.matrix = SUNDenseMatrix(size, size, s.context);
  check(s.matrix != nullptr, "SUNDenseMatrix");
  s.solver = SUNLinSol_Dense(s.y, s.matrix, s.context);
  check(s.solver != nullptr, "SUNLinSol_Dense");
  s.cvode = CVodeCreate(CV_BDF, s.context);
  check(s.cvode != nullptr, "CVodeCreate");
  check(CVodeInit(s.cvode, Impl::f, 0.0, s.y) == CV_SUCCESS, "CVodeInit");
  check(CVodeSStolerances(s.cvode, relative_tolerance, absolute_tolerance) == CV_SUCCESS,
        "CVodeSStolerances");
  check(CVodeSetUserData(s.cvode, &s) == CV_SUCCESS, "CVodeSetUserData");
  check(CVodeSetLinearSolver(s.cvode, s.solver, s.matrix) == CV_SUCCESS, "CVodeSetLinearSolver");
  // Without the caller's Jacobian CVODE forms it by difference quotients.
  if (s.jacobian) check(CVodeSetJacFn(s.cvode, Impl::jac) == CV_SUCCESS, "CVodeSetJacFn");
  check(CVodeSetMaxNumSteps(s.cvode, 20000) == CV_SUCCESS, "CVodeSetMaxNumSteps");
  // Its messages go to stderr by default; failures reach the caller as text instead.
  CVodeSetErrHandlerFn(
      s.cvode, [](int, const char*, const char*, char*, void*) {}, nullptr);
}

StiffIntegrator::~StiffIntegrator() = default;

long StiffIntegrator::steps() const {
  return impl_->steps;
}

bool StiffIntegrator::integrate(double t0, double t1, double* state, std::string* failure) {
  Impl& s = *impl_;
  std::copy(state, state + s.size, s.backup.begin());
  std::copy(state, state + s.size, N_VGetArrayPointer(s.y));
  CVodeReInit(s.cvode, t0, s.y);
  CVodeSetStopTime(s.cvode, t1);
  sunrealtype t = t0;
  const int flag = CVode(s.cvode, t1, s.y, &t, CV_NORMAL);
  long steps = 0;
  CVodeGetNumSteps(s.cvode, &steps);
  s.steps = steps;
  if (flag < 0) {
    if (failure) {
      std::ostringstream os;
      char* name = CVodeGetReturnFlagName(flag);  // malloc'ed by SUNDIALS
      os << "CVODE failed at t = " << t << " (" << name << ")";
      free(name);
      *failure = os.str();
    }
    std::copy(s.backup.begin(), s.backup.end(), state);
    return false;
  }
  std::copy(N_VGetArrayPointer(s.y), N_VGetArrayPointer(s.y) + s.size, state);
  return true;
}

}  // namespace nlobs
