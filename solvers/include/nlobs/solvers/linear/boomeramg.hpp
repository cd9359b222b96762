#pragma once
// Algebraic multigrid as a Krylov preconditioner: hypre's BoomerAMG [HY02], one or more V-cycles
// of a hierarchy built from J alone (no grid): M⁻¹ r ≈ J⁻¹ r at O(nnz) cost per cycle, with a
// convergence rate that does not degrade as n grows on the elliptic operators (2-D Bratu, the
// Laplacian) where ILU(0)'s Krylov iteration count grows like √n.
//
// hypre is an MPI library. The preconditioner runs on MPI_COMM_SELF (each process its own J);
// it starts MPI itself as a singleton (MPI_THREAD_SERIALIZED) at the first setup when the
// program has not, and finalises it at exit; otherwise it uses the program's MPI. Calls into
// hypre are serialised by one lock (hypre keeps global state, its error flag among it): several
// threads may each hold a BoomerAmgPreconditioner, and their setups and applications take
// turns. A program that starts MPI itself below MPI_THREAD_SERIALIZED (MPI_Init, or PETSc's
// FUNNELED) may use it from the thread that started MPI only; setup() elsewhere is refused.
// J must store its whole diagonal (as for ILU(0); sparse_autodiff_problem's patterns do).
//
// Built when hypre (libhypre-dev) and MPI were found at configure time (CMake option
// NLOBS_WITH_HYPRE); otherwise boomeramg_available() is false and the constructor throws
// InvalidInput saying so.
#include <memory>

#include "nlobs/solvers/linear/linear_solver.hpp"

namespace nlobs {

struct BoomerAmgOptions {
  // θ of the classical strength of connection [RS87]: −a_ij ≥ θ max_k(−a_ik). In (0, 1);
  // hypre's and PETSc's default 0.25 suits 2-D operators, hypre's manual advises 0.5 in 3-D.
  double strong_threshold = 0.25;
  // V-cycles per application of M⁻¹, ≥ 1 (at most 100).
  int cycles = 1;
  void validate() const;  // InvalidInput naming the field and its value
};

bool boomeramg_available();

class BoomerAmgPreconditioner final : public LinearPreconditioner {
 public:
  explicit BoomerAmgPreconditioner(BoomerAmgOptions options = {});
  ~BoomerAmgPreconditioner() override;
  BoomerAmgPreconditioner(const BoomerAmgPreconditioner&) = delete;
  BoomerAmgPreconditioner& operator=(const BoomerAmgPreconditioner&) = delete;

  std::string_view name() const override { return "boomeramg"; }
  // kInvalidInput: J empty or not square; kNonFinite: a NaN or infinity (its row named);
  // kSingular: a diagonal entry not stored (its row named), or hypre's setup refusing J (a zero
  // diagonal entry, for one: hypre's error code and description in message());
  // kPackageFailure: MPI or hypre cannot run here (MPI finalised, the thread rule above), or
  // hypre failed to build its objects. A failed setup leaves nothing to apply.
  LinearStatus setup(const SparseJacobian& jac) override;
  // z = M⁻¹ r by `cycles` V-cycles from z = 0. Copies r and z into hypre's vectors, no
  // allocation of ours; hypre's cycle allocates two small work arrays per call. z is all NaN,
  // message() saying why, before a successful setup, for r of the wrong size, or when hypre
  // fails.
  void apply(const Vector<Dynamic>& r, Vector<Dynamic>& z) override;
  // Levels of the last hierarchy (0 before a successful setup).
  int levels() const;

 private:
  struct Impl;
  BoomerAmgOptions options_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace nlobs
