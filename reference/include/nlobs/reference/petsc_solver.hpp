#pragma once
// PETSc's SNES as a reference solver for the same square systems our engines solve, on one
// process (PETSC_COMM_SELF). Set up as PETSc's own drivers set it up for a residual with a known
// nonzero pattern (SNES ex5 run with -snes_fd_color): a SeqAIJ Jacobian of F's pattern, filled by
// PETSc's coloured finite differences (SNESComputeJacobianDefaultColor: PETSc colours the pattern
// itself), and PETSc's defaults for the rest — for newtonls the backtracking (bt) line search,
// GMRES(30) with ILU(0) and a KSP rtol of 1e-5 (-snes_ksp_ew for Eisenstat–Walker). Options
// reach one solver only (a private options database for the SNES, its line search, KSP and PC).
// When nlobs starts PETSc, PETSC_OPTIONS and ~/.petscrc do not reach its solvers; in a program
// that started PETSc itself, what PETSc makes during a solve (the colouring) reads the program's
// options. The PETSc and MPI headers are private: nothing here includes them. Available when
// nlobs was built with PETSc (NLOBS_WITH_PETSC, on when pkg-config finds it): petsc_available().
// Not thread-safe: PETSc's error-handler stack is global; solve on one thread at a time.
#include <Eigen/Core>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace nlobs::reference {

// False when nlobs was built without PETSc: the constructor then throws std::invalid_argument.
bool petsc_available();

// Initialises PETSc (and MPI, as a singleton process, when nobody has: without Open MPI's signal
// handlers or daemon) once per process; later calls return at once. The first takes ~0.3 s
// (MPI's start): a benchmark calls it before timing. PETSc is finalised at exit (unless the
// program finalised MPI first). std::runtime_error when PETSc cannot start; an MPI that cannot
// start ends the process (MPI's own rule).
void initialize_petsc();

struct PetscSnesOptions {
  // A SNESType: "newtonls", "newtontr", "ngmres", "anderson", "qn", "nrichardson" (or another
  // type PETSc 3.18 knows; an unknown one is refused).
  std::string type = "newtonls";
  // PETSc options for this solver, as on a PETSc command line: {"-ksp_type", "bcgs"},
  // {"-snes_mf", ""}. Keys are -snes_…, -ksp_… or -pc_…, of lower-case letters, digits and '_';
  // values of letters, digits and "._+-" (no paths). Viewers only those that print to standard
  // output (-snes_monitor, -ksp_converged_reason, -snes_view, …; petsc_option_rules.hpp), without
  // a value or =ascii: no option writes a file, opens a window or a socket. Refused as well:
  // -snes_type (the name's TYPE says it), -snes_fd and -snes_fd_color (an uncounted Jacobian),
  // and an option SNESSetFromOptions does not read (std::invalid_argument naming it), such as
  // one read only later (PCBJACOBI's -sub_…, MatColoring's -mat_…).
  std::vector<std::pair<std::string, std::string>> options{};
  // SNESSetTolerances: converged when ‖F‖₂ ≤ absolute_tolerance or ≤ relative_tolerance ‖F(x₀)‖₂,
  // or when ‖Δx‖₂ ≤ step_tolerance ‖x‖₂ (PETSc's stol, its default 1e-8). Each ≥ 0.
  double absolute_tolerance = 1e-10;
  double relative_tolerance = 0.0;
  double step_tolerance = 1e-8;
  long max_iterations = 10000;  // SNES's maxit, ≥ 1
  // Every evaluation of F counts (PETSc's own, its coloured differences' and the final check):
  // an evaluation beyond max_evaluations − 1 is refused before F is called (SNES stops with an
  // error) and the status is "max_evaluations". 0: no limit; otherwise at least 2.
  long max_evaluations = 0;
};

// F's nonzero pattern as compressed rows: row_starts of size n + 1, columns sorted within a row.
// Empty: every entry (a dense pattern, n² entries; n ≤ 2000). The diagonal is added where
// missing (ILU needs it in the structure).
struct PetscPattern {
  std::vector<long> row_starts{}, columns{};
};

struct PetscSnesResult {
  int reason = 0;           // SNESGetConvergedReason (0 when SNESSolve failed with an error)
  std::string reason_name;  // SNESConvergedReasons[reason]: "CONVERGED_FNORM_ABS", ...
  std::string error;        // PETSc's error message when SNESSolve returned an error
  // reason > 0 and the returned x is finite with ‖F(x)‖∞ ≤ check_tolerance (one more
  // evaluation, counted): PETSc's step test (CONVERGED_SNORM_RELATIVE) stops on the step alone.
  bool success = false;
  std::string reason_text;     // why success is false although reason > 0
  double residual = 0.0;       // ‖F(x)‖∞ at the returned x
  long iterations = 0;         // SNESGetIterationNumber
  long linear_iterations = 0;  // SNESGetLinearSolveIterations
  long evaluations = 0;        // every evaluation of F, counted at the callback
  long jacobian_evaluations = 0;
  bool budget_spent = false;  // an evaluation beyond max_evaluations was refused
  // "converged"; "non_finite" or "residual_above_tolerance" (reason > 0 that does not stand);
  // "max_evaluations" (budget_spent); "function_error" (F threw); else PETSc's reason in lower
  // case ("diverged_line_search", "diverged_max_it", ...), or "petsc_error".
  std::string status() const;
};

class PetscSnesSolver {
 public:
  using Function = std::function<void(const Eigen::VectorXd&, Eigen::VectorXd&)>;

  // F: R^n → R^n. Sets SNES up (type, options, the Jacobian's matrix and colouring); solve()
  // runs it. std::invalid_argument for options out of range, an option PETSc refuses or leaves
  // unused, a malformed pattern, or a build without PETSc.
  PetscSnesSolver(int n, PetscSnesOptions options, Function function, PetscPattern pattern = {},
                  double check_tolerance = 1e-8);
  ~PetscSnesSolver();
  PetscSnesSolver(const PetscSnesSolver&) = delete;
  PetscSnesSolver& operator=(const PetscSnesSolver&) = delete;

  // x: initial guess in, SNES's answer out. An exception F throws reaches the caller (after
  // SNES has stopped); a solve that ended in an error (F threw, the budget refused, PETSc
  // failed) has the next one make PETSc's objects anew.
  PetscSnesResult solve(Eigen::VectorXd& x);

  // "petsc:TYPE" or "petsc:TYPE:-key=value:-flag…" → the options it names (type and options);
  // std::invalid_argument for a malformed name. is_name: the "petsc:" prefix only.
  static PetscSnesOptions parse_name(const std::string& name);
  static bool is_name(const std::string& name);
  // The six names the suite lists: petsc:newtonls, newtontr, ngmres, anderson, qn, nrichardson.
  static std::vector<std::string> names();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace nlobs::reference
