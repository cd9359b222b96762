#pragma once
// What the engines with a sparse path (newton, pseudo-transient) share: whether a solve takes it,
// the refusal of a declared pattern where an engine would go dense, and the linear solve — the
// linear solver chosen for the problem's pattern, A set up and A x = b solved, its failures as
// the engine's statuses.
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "nlobs/common/invalid_input.hpp"
#include "nlobs/solvers/linear/linear_solver.hpp"
#include "nlobs/solvers/linear/make_linear_solver.hpp"
#include "nlobs/solvers/problem.hpp"
#include "nlobs/solvers/status.hpp"
#include "nlobs/solvers/summary.hpp"
#include "nlobs/solvers/types.hpp"

namespace nlobs::detail {

// An engine option naming the sparse path's linear solver: "auto", "dense" or a
// make_linear_solver spec; anything else is refused naming `option`.
inline void check_linear_solver_option(const char* option, const std::string& spec) {
  if (spec == "auto" || spec == "dense") return;
  try {
    make_linear_solver(spec);
  } catch (const InvalidInput& e) {
    throw InvalidInput(std::string(option) + ": " + e.what() + " (or auto, dense)");
  }
}

// An engine whose linear solver is `spec` takes the sparse path unless spec is "dense" or
// something else sends it to the dense one (`dense_reason`: "the trust region"; nullptr for
// nothing).
inline bool takes_sparse_path(const std::string& spec, const char* dense_reason) {
  return spec != "dense" && dense_reason == nullptr;
}

// A declared sparse Jacobian says the dense one may be out of reach: where the engine would take
// the dense path for `dense_reason`, InvalidInput naming it and `remedy`. A pattern still to be
// detected is not refused (the dense path then, as before detection).
template <int N>
void refuse_dense_path_for_declared(std::string_view engine, const FixedPointProblem<N>& problem,
                                    const std::string& spec, const char* dense_reason,
                                    const char* remedy) {
  const SparseJacobianState* state = problem.sparse_jacobian_state().get();
  if (state == nullptr || !state->declared() || spec == "dense" || dense_reason == nullptr) {
    return;
  }
  throw InvalidInput(std::string(engine) + ": " + dense_reason +
                     " is not on the sparse path yet; " + remedy);
}

// The sparse Jacobian a solve from x uses (detected at x first if that is still to do), or
// nullptr for the dense path.
template <int N>
const SparseJacobianSource* sparse_path_source(const FixedPointProblem<N>& problem,
                                               const Vector<N>& x, const std::string& spec,
                                               const char* dense_reason) {
  if (!takes_sparse_path(spec, dense_reason)) return nullptr;
  return problem.sparse_residual_jacobian(x);
}

class SparseLinearStep {
 public:
  // The solver for `spec` (make_linear_solver's, or "auto": choose_linear_solver) on `pattern`.
  void choose(const std::string& spec, const SparsityPattern& pattern, Index n) {
    solver_ = make_linear_solver(choose_linear_solver(spec, pattern, n));
  }
  const LinearSolver& solver() const { return *solver_; }
  // Sets up A (factor, or build the preconditioner) for resolve().
  LinearStatus setup(const SparseJacobian& a) { return solver_->setup(a); }
  bool iterative() const { return solver_->iterative(); }

  // A x = b, x to a relative residual `tolerance` for a Krylov solver (a direct one solves
  // exactly). A Krylov answer above the tolerance is accepted when its relative residual is below
  // `accept_below` (≥ tolerance): Newton passes 1, since with ‖F + J Δx‖ < ‖F‖ the step is still
  // a descent direction of ‖F‖² (Fᵀ J Δx = Fᵀ r − ‖F‖² < 0).
  LinearStatus solve(const SparseJacobian& a, const Vector<Dynamic>& b, Vector<Dynamic>& x,
                     double tolerance, double accept_below) {
    const LinearStatus status = solver_->setup(a);
    if (status != LinearStatus::kSolved) return status;
    return resolve(b, x, tolerance, accept_below);
  }
  // The same with the matrix of the last setup (modified Newton: its factorisation reused).
  LinearStatus resolve(const Vector<Dynamic>& b, Vector<Dynamic>& x, double tolerance,
                       double accept_below) {
    const LinearStatus status = solver_->solve(b, x, tolerance);
    if (status == LinearStatus::kNotConverged && solver_->stats().last_residual < accept_below) {
      return LinearStatus::kSolved;
    }
    return status;
  }

  // A failed solve as the engine's status, its message the linear solver's: non-finite values
  // are kNonFinite; a direct solver's zero pivot is the matrix's (kSingularJacobian); a Krylov
  // solver's breakdown, budget or singular preconditioner need not be (BiCGSTAB breaks down on
  // regular systems): kSolverFailure. nullopt for kSolved.
  std::optional<Status> failure(LinearStatus status, std::string& message) const {
    if (status == LinearStatus::kSolved) return std::nullopt;
    message = solver_->message();
    if (status == LinearStatus::kNonFinite) return Status::kNonFinite;
    if (status == LinearStatus::kSingular && !solver_->iterative()) {
      return Status::kSingularJacobian;
    }
    return Status::kSolverFailure;
  }

  // The Summary's linear_solver, linear_setups and linear_iterations.
  void report(Summary& summary) const {
    summary.linear_solver = std::string(solver_->name());
    summary.linear_setups = solver_->stats().setups;
    summary.linear_iterations = solver_->stats().iterations;
  }

 private:
  std::shared_ptr<LinearSolver> solver_;  // (engines stay copyable)
};

}  // namespace nlobs::detail
