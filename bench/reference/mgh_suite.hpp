#pragma once
// `nlobs suite mgh`: every listed solver on every (MGH problem, start scale) pair, judged the
// same way for all: solved when ‖F(x)‖₂ ≤ 1e-8 at the point the solver returns.
#include <functional>
#include <string>
#include <vector>

namespace nlobs::reference {

struct SuiteRow {
  std::string problem;
  int n = 0;
  double start_scale = 1.0;
  std::string solver;
  bool solved = false;
  double residual = 0.0;  // ‖F(x)‖₂ at the returned x (inf if not finite)
  long f_evals = 0;
  long j_evals = 0;
  double ns = 0.0;     // wall time per solve
  std::string status;  // the solver's own account
};

struct SuiteOptions {
  std::vector<double> start_scales = {1.0, 10.0, 100.0};
  double solved_threshold = 1e-8;  // on ‖F‖₂
  // Every solver gets the same budget of F evaluations: 1000 (n + 1).
  long evaluations_per_dimension = 1000;
  // Called after each (problem, start) pair, e.g. for a progress line.
  std::function<void(int done, int total)> progress;
};

// Our engines (registry specs) in the default order, then the references.
std::vector<std::string> default_suite_solvers();
std::vector<std::string> reference_suite_solvers();  // minpack:hybrj, kinsol:newton, gsl:...

// Throws std::invalid_argument for an unknown solver (listing the valid names).
std::vector<SuiteRow> run_mgh_suite(const std::vector<std::string>& solvers,
                                    const SuiteOptions& options = {});

// Splits a --solvers/--engines list on commas, keeping "key=value" items with the spec
// before them: "anderson:m=3,damping=0.5,newton" -> {"anderson:m=3,damping=0.5", "newton"}.
std::vector<std::string> split_spec_list(const std::string& list);

}  // namespace nlobs::reference
