// BoomerAMG when nlobs was configured without hypre (NLOBS_WITH_HYPRE off): the type exists, so
// that code naming it compiles everywhere, and refuses to be built.
#include <string>

#include "nlobs/common/invalid_input.hpp"
#include "nlobs/solvers/linear/boomeramg.hpp"

namespace nlobs {

struct BoomerAmgPreconditioner::Impl {};

bool boomeramg_available() {
  return false;
}

BoomerAmgPreconditioner::BoomerAmgPreconditioner(BoomerAmgOptions options) : options_(options) {
  options_.validate();
  throw InvalidInput(
      "preconditioner boomeramg: nlobs was built without hypre (configure with "
      "-DNLOBS_WITH_HYPRE=ON after apt-get install libhypre-dev)");
}

BoomerAmgPreconditioner::~BoomerAmgPreconditioner() = default;

int BoomerAmgPreconditioner::levels() const {
  return 0;
}

LinearStatus BoomerAmgPreconditioner::setup(const SparseJacobian&) {
  return LinearStatus::kPackageFailure;
}

void BoomerAmgPreconditioner::apply(const Vector<Dynamic>&, Vector<Dynamic>&) {}

}  // namespace nlobs
