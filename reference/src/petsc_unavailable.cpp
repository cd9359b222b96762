// nlobs built without PETSc (NLOBS_WITH_PETSC off, or pkg-config found no PETSc): the PETSc
// reference solver refuses to be made, with the reason.
#include <stdexcept>

#include "nlobs/reference/petsc_solver.hpp"

namespace nlobs::reference {

namespace {
[[noreturn]] void unavailable() {
  throw std::invalid_argument(
      "PETSc SNES: this nlobs was built without PETSc (configure with -DNLOBS_WITH_PETSC=ON and "
      "Debian's petsc-dev installed)");
}
}  // namespace

bool petsc_available() {
  return false;
}
void initialize_petsc() {
  unavailable();
}

struct PetscSnesSolver::Impl {};

PetscSnesSolver::PetscSnesSolver(int, PetscSnesOptions, Function, PetscPattern, double) {
  unavailable();
}
PetscSnesSolver::~PetscSnesSolver() = default;
PetscSnesResult PetscSnesSolver::solve(Eigen::VectorXd&) {
  unavailable();
}

}  // namespace nlobs::reference
