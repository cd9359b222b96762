#include "nlobs/reference/reference_engines.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "nlobs/common/printable.hpp"
#include "nlobs/reference/kinsol_solver.hpp"
#include "nlobs/reference/petsc_solver.hpp"
#include "nlobs/reference/root_reference.hpp"
#include "nlobs/registry/problem_sets.hpp"  // kMaxProblemDimension
#include "nlobs/solvers/sparse/pattern_bandwidths.hpp"
#include "nlobs/solvers/sparse/sparse_jacobian.hpp"
#include "nlobs/solvers/sparse/sparse_jacobian_source.hpp"
#include "nlobs/solvers/sparse/sparsity_pattern.hpp"

namespace nlobs::reference {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// What a call into the problem throws, once the problem has thrown, to a library whose own
// callback catches exceptions and turns one into "stop" (KINSOL's and PETSc's wrappers: -1, an
// unrecoverable failure). Never seen outside this file: solve() rethrows the problem's own.
struct LibraryStop {};

// F and G of one solve as a C library calls them. An exception is kept (the first) and
// nothing unwinds through C: a library whose callbacks catch (`stop_by_throwing`: KINSOL,
// PETSc) gets LibraryStop, which its wrapper turns into an unrecoverable failure, from that
// call and every later one; the others (MINPACK, GSL) get NaN, on which they stop. The problem
// is not called again. solve() rethrows the kept exception.
class GuardedCalls {
 public:
  GuardedCalls(const FixedPointProblem<Dynamic>& problem, bool stop_by_throwing)
      : problem_(problem), stop_by_throwing_(stop_by_throwing) {}

  // F: the problem's residual form, else G(x) − x.
  void residual(const Eigen::VectorXd& x, Eigen::VectorXd& f) {
    f.resize(problem_.size());
    if (!guard([&] {
          if (problem_.has_residual()) {
            problem_.residual(x, f);
          } else {
            problem_.evaluate(x, f);
            f -= x;
          }
        })) {
      f.setConstant(kNaN);
    }
  }
  // G, for KINSOL's fixed-point strategies.
  void fixed_point(const Eigen::VectorXd& x, Eigen::VectorXd& g) {
    g.resize(problem_.size());
    if (!guard([&] { problem_.evaluate(x, g); })) g.setConstant(kNaN);
  }
  // ∂F: the residual form's, else ∂G − I. Only when has_jacobian().
  void jacobian(const Eigen::VectorXd& x, Eigen::MatrixXd& j) {
    const Index n = problem_.size();
    j.resize(n, n);
    if (!guard([&] {
          if (problem_.has_residual()) {
            problem_.residual_jacobian(x, j);
          } else {
            problem_.jacobian(x, j);
            j.diagonal().array() -= 1.0;
          }
        })) {
      j.setConstant(kNaN);
    }
  }
  // Any other call into the problem (its sparse Jacobian), guarded alike: false when it threw
  // now or before (the caller then fills NaN).
  template <typename Call>
  bool guard(Call&& call) {
    if (!error_) {
      try {
        call();
        return true;
      } catch (...) {
        error_ = std::current_exception();
      }
    }
    if (stop_by_throwing_) throw LibraryStop{};
    return false;
  }
  bool has_jacobian() const { return problem_.has_jacobian(); }

  // F (and ∂F when the problem has it) as the RootProblem MINPACK's and GSL's drivers take.
  RootProblem<Dynamic> root() {
    const Index n = problem_.size();
    auto f = [this](const Eigen::VectorXd& x, Eigen::VectorXd& out) { residual(x, out); };
    if (!has_jacobian()) return RootProblem<Dynamic>::from_map(f, n, n);
    return RootProblem<Dynamic>::with_jacobian(
        f, [this](const Eigen::VectorXd& x, Eigen::MatrixXd& j) { jacobian(x, j); }, n, n,
        problem_.jacobian_source());
  }
  // F's sparse Jacobian, declared or detected at x (null without one).
  const SparseJacobianSource* sparse(const Eigen::VectorXd& x) const {
    return problem_.has_residual() ? problem_.sparse_residual_jacobian(x) : nullptr;
  }
  std::string sparse_note() const {
    return problem_.sparse_jacobian_state() ? problem_.sparse_jacobian_state()->note()
                                            : std::string("the problem declares none");
  }
  const std::shared_ptr<detail::SparseJacobianState>& sparse_state() const {
    return problem_.sparse_jacobian_state();
  }

  void rethrow() const {
    if (error_) std::rethrow_exception(error_);
  }

 private:
  const FixedPointProblem<Dynamic>& problem_;
  bool stop_by_throwing_;
  std::exception_ptr error_;
};

// What a library said of one run.
struct LibraryRun {
  std::string status;  // its account: "converged", "xtol_too_small", ...
  long iterations = 0, f_evals = 0, j_evals = 0, linear_iterations = 0;
  std::string message;
  // ‖F‖∞ at the returned x, from the library's check of its answer (KINSOL's under its
  // scaling, ‖D_f F‖∞); NaN when it made none.
  double residual = kNaN;
};

// The Status nearest a library's account (Summary::library_status keeps the account itself).
Status nearest_status(const std::string& s) {
  if (s == "converged") return Status::kConverged;
  if (s == "max_evaluations") return Status::kMaxEvaluations;
  if (s == "max_iterations" || s == "diverged_max_it") return Status::kMaxIterations;
  if (s == "non_finite" || s == "function_error" || s == "diverged_function_domain" ||
      s == "diverged_fnorm_nan") {
    return Status::kNonFinite;
  }
  if (s == "singular_jacobian") return Status::kSingularJacobian;
  if (s == "xtol_too_small" || s == "not_making_progress" || s == "not_making_progress_jacobian") {
    return Status::kStagnated;
  }
  return Status::kSolverFailure;
}

int clamp_count(long count) {
  return static_cast<int>(std::min<long>(count, std::numeric_limits<int>::max()));
}

// An engine that hands F (or G) to a C library: solve() checks the call, guards the problem's
// calls, runs the library and reports in a Summary.
class LibraryEngine : public Engine<Dynamic> {
 public:
  Summary solve(const FixedPointProblem<Dynamic>& problem, Eigen::VectorXd& x) final {
    const std::string who = label();
    if (x.size() != problem.size()) {
      throw InvalidInput(who + ": the initial guess has " + std::to_string(x.size()) +
                         " entries, the problem " + std::to_string(problem.size()));
    }
    if (!x.allFinite()) throw InvalidInput(who + ": the initial guess is not finite");
    if (budget() < 2) {
      throw InvalidInput(who + ": max_evaluations = " + std::to_string(budget()) +
                         " is invalid: a reference engine needs at least 2 (its library's and "
                         "the check of its answer)");
    }
    if (dense() && problem.size() > kMaxProblemDimension) {
      throw InvalidInput(
          who + " keeps dense n x n matrices: not run at n = " + std::to_string(problem.size()) +
          ", above " + std::to_string(kMaxProblemDimension) +
          " (kinsol:newton-band, -klu and -spgmr are KINSOL's sparse forms)");
    }
    GuardedCalls calls(problem, stop_by_throwing());
    LibraryRun run;
    try {
      run = run_library(calls, x);
    } catch (const LibraryStop&) {  // PETSc's wrapper rethrows what its callback caught
      calls.rethrow();              // a stop follows a kept exception: this throws it
      throw;
    } catch (const InvalidInput&) {
      throw;
    } catch (const std::invalid_argument& refused) {  // the library's set-up refused its options
      calls.rethrow();  // unless the problem threw first (a detection at x, say)
      throw InvalidInput(who + ": " + refused.what());
    }
    calls.rethrow();
    Summary s;
    s.engine = name();
    s.status = nearest_status(run.status);
    s.library_status = run.status;
    s.message = run.message;
    s.iterations = clamp_count(run.iterations);
    s.function_evaluations = clamp_count(run.f_evals);
    s.jacobian_evaluations = clamp_count(run.j_evals);
    s.linear_iterations = clamp_count(run.linear_iterations);
    s.residual_norm = run.residual;
    s.record_answer(x, options_.stop);
    return s;
  }

 protected:
  explicit LibraryEngine(SolverOptions options) : Engine<Dynamic>(std::move(options)) {}
  long budget() const { return options_.stop.max_evaluations; }
  // Whether the library's callbacks catch an exception and stop (GuardedCalls).
  virtual bool stop_by_throwing() const { return false; }
  // True for the methods that keep dense n × n matrices.
  virtual bool dense() const = 0;
  virtual LibraryRun run_library(GuardedCalls& calls, Eigen::VectorXd& x) = 0;
};

// The common keys the reference engines do not take (their libraries' own stop tests do the
// work): each engine leaves out those it has no key of its own for.
const std::vector<std::string> kLibraryStops = {"step_tolerance", "residual_tolerance",
                                                "max_iterations", "progress_window"};

std::vector<std::string> without(std::initializer_list<const char*> own) {
  std::vector<std::string> out = kLibraryStops;
  for (const char* key : own) std::erase(out, key);
  return out;
}

// The value of `key` when the spec gives it, finite and > 0 (InvalidInput naming it otherwise);
// `fallback` when it does not.
double positive(EngineSpecReader& spec, const std::string& key, double fallback) {
  const std::optional<double> given = spec.number(key);
  if (!given) return fallback;
  const double v = *given;
  if (!(v > 0.0) || !std::isfinite(v)) {
    throw InvalidInput("engine option " + key + " = " + std::to_string(v) +
                       " is invalid: must be finite and > 0");
  }
  return v;
}

// MINPACK hybrj as hybrj1 runs it (root_reference.hpp).
class MinpackEngine final : public LibraryEngine {
 public:
  MinpackEngine(ReferenceOptions options, SolverOptions solver)
      : LibraryEngine(std::move(solver)), library_options_(options) {}
  std::string_view name() const override { return "minpack"; }

  static EngineRegistry<Dynamic>::Entry entry() {
    return {.name = "minpack",
            .description = "MINPACK hybrj (Powell hybrid, cminpack) as its hybrj1 driver runs it",
            .options = {{"<word>", "hybrj (the only method; default)"},
                        {"xtol", "hybrj's relative step tolerance; default sqrt(eps)"},
                        {"residual_tolerance",
                         "hybrj's converged stands at |F|inf <= this (one more evaluation); "
                         "default 1e-8"}},
            .examples = {"minpack:hybrj"},
            .make =
                [](EngineSpecReader& spec, SolverOptions solver) {
                  (void)spec.word({"hybrj"});
                  ReferenceOptions o;
                  o.minpack_xtol = positive(spec, "xtol", o.minpack_xtol);
                  o.residual_tolerance = positive(spec, "residual_tolerance", o.residual_tolerance);
                  return std::unique_ptr<Engine<Dynamic>>(
                      std::make_unique<MinpackEngine>(o, std::move(solver)));
                },
            .without_common = without({"residual_tolerance"})};
  }

 private:
  bool dense() const override { return true; }
  LibraryRun run_library(GuardedCalls& calls, Eigen::VectorXd& x) override {
    if (!calls.has_jacobian()) {
      throw InvalidInput(label() + " needs the problem's Jacobian (hybrj takes dF)");
    }
    ReferenceOptions o = library_options_;
    o.max_evaluations = budget();
    const ReferenceResult r = solve_minpack_hybrj(calls.root(), x, o);
    return {r.status, r.iterations, r.f_evals, r.j_evals, 0, {}, r.residual};
  }
  ReferenceOptions library_options_;
};

// GSL's hybridsj and gnewton (root_reference.hpp).
class GslEngine final : public LibraryEngine {
 public:
  GslEngine(std::string method, ReferenceOptions options, SolverOptions solver)
      : LibraryEngine(std::move(solver)), method_(std::move(method)), library_options_(options) {}
  std::string_view name() const override { return "gsl"; }

  static EngineRegistry<Dynamic>::Entry entry() {
    return {
        .name = "gsl",
        .description =
            "GSL multiroot: hybridsj (scaled hybrid) or gnewton (globally "
            "convergent Newton), with dF",
        .options = {{"<word>", "hybridsj (default) or gnewton"},
                    {"tolerance",
                     "GSL's tests: sum |F_i| < tolerance, or a step below tolerance/100; "
                     "default 1e-10"},
                    {"residual_tolerance",
                     "GSL's converged stands at |F|inf <= this (one more evaluation); "
                     "default 1e-8"}},
        .examples = {"gsl:hybridsj", "gsl:gnewton"},
        .make =
            [](EngineSpecReader& spec, SolverOptions solver) {
              const std::string method = spec.word({"hybridsj", "gnewton"}).value_or("hybridsj");
              ReferenceOptions o;
              o.tolerance = positive(spec, "tolerance", o.tolerance);
              o.residual_tolerance = positive(spec, "residual_tolerance", o.residual_tolerance);
              return std::unique_ptr<Engine<Dynamic>>(
                  std::make_unique<GslEngine>(method, o, std::move(solver)));
            },
        .without_common = without({"residual_tolerance"})};
  }

 private:
  bool dense() const override { return true; }
  LibraryRun run_library(GuardedCalls& calls, Eigen::VectorXd& x) override {
    if (!calls.has_jacobian()) {
      throw InvalidInput(label() + " needs the problem's Jacobian (GSL's fdf solvers take dF)");
    }
    ReferenceOptions o = library_options_;
    o.max_evaluations = budget();
    const ReferenceResult r = solve_gsl(method_, calls.root(), x, o);
    return {r.status, r.iterations, r.f_evals, r.j_evals, 0, {}, r.residual};
  }
  std::string method_;
  ReferenceOptions library_options_;
};

// ∂F for kinsol:newton-klu: the problem's sparse Jacobian (declared or detected at x), its values
// copied in the pattern's row order, evaluated through `guarded` (the solve's GuardedCalls: the
// set-up is kept across solves). InvalidInput without one.
template <typename Guarded>
KinsolSparseJacobian kinsol_sparse_jacobian(const GuardedCalls& calls, const Eigen::VectorXd& x,
                                            const std::string& who, Guarded guarded) {
  const SparseJacobianSource* source = calls.sparse(x);
  if (!source) {
    throw InvalidInput(who + " needs a sparse Jacobian, and F has none (" + calls.sparse_note() +
                       ")");
  }
  const SparsityPattern& pattern = *source->pattern;
  KinsolSparseJacobian out;
  out.row_starts.assign(pattern.row_start.begin(), pattern.row_start.end());
  out.columns.assign(pattern.columns.begin(), pattern.columns.end());
  // Through the problem's state: its lock guards the workspace the problem's copies share.
  std::shared_ptr<detail::SparseJacobianState> state = calls.sparse_state();
  auto jac = std::make_shared<SparseJacobian>();
  const auto nonzeros = static_cast<Eigen::Index>(out.columns.size());
  out.values = [state, jac, nonzeros, guarded](const Eigen::VectorXd& at, const Eigen::VectorXd& f,
                                               double* values) {
    guarded([&] { state->evaluate(at, f, *jac); });
    if (jac->nonZeros() != nonzeros) {  // the callback makes this KINSOL's Jacobian failure
      throw std::logic_error("the sparse Jacobian's structure is not its pattern's");
    }
    std::copy(jac->valuePtr(), jac->valuePtr() + nonzeros, values);
  };
  return out;
}

// The KINSOL options that decide its set-up: a solve with the same ones reuses the solver.
bool same_setup(const KinsolOptions& a, const KinsolOptions& b) {
  return a.strategy == b.strategy && a.linear_solver == b.linear_solver &&
         a.lower_bandwidth == b.lower_bandwidth && a.upper_bandwidth == b.upper_bandwidth &&
         a.max_setup_calls == b.max_setup_calls && a.tolerance == b.tolerance &&
         a.step_tolerance == b.step_tolerance && a.max_iterations == b.max_iterations &&
         a.max_evaluations == b.max_evaluations && a.max_newton_step == b.max_newton_step &&
         a.u_scale.size() == b.u_scale.size() && a.u_scale == b.u_scale &&
         a.f_scale.size() == b.f_scale.size() && a.f_scale == b.f_scale;
}

// KINSOL (kinsol_solver.hpp), set up as the suite's drivers set it up. For exact Newton and the
// fixed-point strategies the set-up (KINSOL's memory, its matrix and linear solver) is kept for
// the next solve of the same size and options — from the same start, say — as KINSOL's own
// drivers re-run KINSol: what a timing of repeated solves then measures is the iteration, as for
// nlobs' engines. Modified Newton is set up at every solve (run_library says why).
class KinsolEngine final : public LibraryEngine {
 public:
  struct Settings {
    std::string form = "newton";  // fp, fp-aa2, newton, newton-band, newton-klu, newton-spgmr
    double residual_tolerance = 1e-10;
    double step_tolerance = 0.0;  // 0: residual_tolerance
    long max_iterations = 0;      // 0: the evaluation budget
  };
  KinsolEngine(Settings settings, SolverOptions solver)
      : LibraryEngine(std::move(solver)), settings_(std::move(settings)) {}
  std::string_view name() const override { return "kinsol"; }
  bool accepts_scaling() const override { return true; }
  // Its fixed-point strategies iterate G: a window estimator gives them a contracting Ψ.
  bool needs_contraction() const override { return settings_.form.rfind("fp", 0) == 0; }

  static EngineRegistry<Dynamic>::Entry entry() {
    return {
        .name = "kinsol",
        .description =
            "SUNDIALS KINSOL: fixed point (Anderson), Newton with line search on a "
            "dense, band, KLU or SPGMR linear solver",
        .options = {{"<word>",
                     "fp, fp-aa2 (Anderson, depth 2), newton (dense, the problem's dF; default), "
                     "newton-band, newton-klu, newton-spgmr (modified Newton)"},
                    {"residual_tolerance", "KINSOL's fnormtol on |D_f F|inf; default 1e-10"},
                    {"step_tolerance",
                     "KINSOL's scsteptol on its scaled step; default residual_tolerance"},
                    {"max_iterations", "KINSOL's iterations; default the evaluation budget"}},
        .examples = {"kinsol:newton", "kinsol:fp-aa2", "kinsol:newton-klu"},
        .make =
            [](EngineSpecReader& spec, SolverOptions solver) {
              Settings s;
              s.form =
                  spec.word({"fp", "fp-aa2", "newton", "newton-band", "newton-klu", "newton-spgmr"})
                      .value_or("newton");
              s.residual_tolerance = positive(spec, "residual_tolerance", s.residual_tolerance);
              // 0 (unset): KINSOL's scsteptol is residual_tolerance.
              s.step_tolerance = positive(spec, "step_tolerance", 0.0);
              s.max_iterations = spec.integer("max_iterations", 1, 1000000000).value_or(0);
              return std::unique_ptr<Engine<Dynamic>>(
                  std::make_unique<KinsolEngine>(std::move(s), std::move(solver)));
            },
        .without_common = without({"residual_tolerance", "step_tolerance", "max_iterations"})};
  }

 private:
  bool dense() const override { return settings_.form == "newton"; }
  bool stop_by_throwing() const override { return true; }

  KinsolOptions options_for(GuardedCalls& calls, const Eigen::VectorXd& x) const {
    const std::string name = "kinsol:" + settings_.form;
    KinsolOptions ko;
    ko.strategy = KinsolSolver::strategy(name).value_or(KinsolStrategy::kNewtonLineSearch);
    ko.tolerance = settings_.residual_tolerance;
    ko.step_tolerance = settings_.step_tolerance;
    ko.u_scale = scaling().u_scale;
    ko.f_scale = scaling().f_scale;
    // KINSOL counts iterations (each at least one evaluation); max_evaluations bounds the
    // evaluations its line search and the final check add.
    const long evaluations = budget();
    ko.max_iterations = settings_.max_iterations > 0 ? settings_.max_iterations : evaluations;
    ko.max_evaluations = evaluations;
    // KINSOL's own maximum step, 1000 ‖u₀‖₂, collapses to 1 at u₀ = 0 (Watson's start, a
    // user's zero start): the same rule measured from 1 instead (docs/solvers.md); ‖u₀‖₂ without
    // overflow and the product at most the largest double (a start of 1e308).
    ko.max_newton_step =
        std::min(std::numeric_limits<double>::max(), 1000.0 * std::max(1.0, x.stableNorm()));
    if (ko.strategy != KinsolStrategy::kNewtonLineSearch) return ko;
    ko.linear_solver = KinsolSolver::linear_solver(name).value_or(KinsolLinearSolver::kDense);
    if (ko.linear_solver == KinsolLinearSolver::kBand) {
      // The widths of F's pattern; the full band without one.
      const SparseJacobianSource* source = calls.sparse(x);
      const Index n = x.size();
      const PatternBandwidths band =
          source ? pattern_bandwidths(*source->pattern) : PatternBandwidths{n - 1, n - 1};
      ko.lower_bandwidth = band.lower;
      ko.upper_bandwidth = band.upper;
    }
    // The band, KLU and SPGMR forms run KINSOL's default, modified Newton; the dense one exact
    // Newton on the problem's Jacobian.
    if (ko.linear_solver != KinsolLinearSolver::kDense) ko.max_setup_calls = 0;
    return ko;
  }

  LibraryRun run_library(GuardedCalls& calls, Eigen::VectorXd& x) override {
    const KinsolOptions ko = options_for(calls, x);
    const bool dense_jacobian = ko.strategy == KinsolStrategy::kNewtonLineSearch &&
                                ko.linear_solver == KinsolLinearSolver::kDense &&
                                calls.has_jacobian();
    const void* sparse_state =
        ko.linear_solver == KinsolLinearSolver::kKlu ? calls.sparse_state().get() : nullptr;
    // Modified Newton (the band, KLU and SPGMR forms) keeps the age of its Jacobian across
    // KINSol calls: a kept set-up would start the next solve from the last one's (measured:
    // kinsol:newton-band on MGH's helical valley took 127 evaluations instead of 152 on its
    // second run). Those are set up afresh for every solve, so that every solve from a start is
    // the first one; exact Newton (a Jacobian every iteration) and the fixed-point strategies
    // carry nothing over and keep theirs.
    const bool carries_state =
        ko.strategy == KinsolStrategy::kNewtonLineSearch && ko.max_setup_calls != 1;
    if (!solver_ || carries_state || x.size() != solved_size_ || !same_setup(ko, built_) ||
        dense_jacobian != built_dense_jacobian_ || sparse_state != built_sparse_state_) {
      solver_.reset();
      const int n = static_cast<int>(x.size());
      if (ko.strategy == KinsolStrategy::kNewtonLineSearch) {
        KinsolSolver::Jacobian jacobian;
        if (dense_jacobian) {
          jacobian = [this](const Eigen::VectorXd& v, Eigen::MatrixXd& j) {
            active_->jacobian(v, j);
          };
        }
        KinsolSparseJacobian sparse;
        if (ko.linear_solver == KinsolLinearSolver::kKlu) {
          sparse = kinsol_sparse_jacobian(calls, x, label(), [this](const auto& call) {
            active_->guard(call);  // throws LibraryStop once the problem threw
          });
        }
        solver_ = std::make_unique<KinsolSolver>(
            n, ko,
            [this](const Eigen::VectorXd& v, Eigen::VectorXd& out) { active_->residual(v, out); },
            std::move(jacobian), std::move(sparse));
      } else {
        solver_ = std::make_unique<KinsolSolver>(
            n, ko, [this](const Eigen::VectorXd& v, Eigen::VectorXd& out) {
              active_->fixed_point(v, out);
            });
      }
      built_ = ko;
      built_dense_jacobian_ = dense_jacobian;
      built_sparse_state_ = sparse_state;
      solved_size_ = x.size();
    }
    active_ = &calls;
    struct Release {
      GuardedCalls*& active;
      ~Release() { active = nullptr; }
    } release{active_};
    const KinsolResult r = solver_->solve(x);
    return {r.status(),          r.iterations, r.evaluations, r.jacobian_evaluations,
            r.linear_iterations, r.reason,     r.residual};
  }

  Settings settings_;
  // The kept set-up and what it was built for.
  std::unique_ptr<KinsolSolver> solver_;
  KinsolOptions built_;
  bool built_dense_jacobian_ = false;
  const void* built_sparse_state_ = nullptr;
  Index solved_size_ = -1;
  GuardedCalls* active_ = nullptr;  // the solve running: the kept solver's functions call it
};

// PETSc SNES (petsc_solver.hpp), set up at every solve as its drivers run it with
// -snes_fd_color.
class PetscEngine final : public LibraryEngine {
 public:
  PetscEngine(PetscSnesOptions options, SolverOptions solver)
      : LibraryEngine(std::move(solver)), library_options_(std::move(options)) {}
  std::string_view name() const override { return "petsc"; }

  static EngineRegistry<Dynamic>::Entry entry() {
    return {.name = "petsc",
            .description =
                "PETSc SNES (newtonls, newtontr, ngmres, anderson, qn, nrichardson) "
                "on PETSc's coloured differences of F's pattern",
            .options = {{"<type>[:-key=value...]",
                         "a SNESType, then PETSc options of the SNES, its KSP and PC "
                         "(docs/solvers.md, \"PETSc SNES\")"}},
            .examples = {"petsc:newtonls", "petsc:newtonls:-ksp_type=gmres:-pc_type=ilu"},
            .make =
                [](EngineSpecReader& spec, SolverOptions solver) {
                  // PETSc's options follow the type as :-key=value; an item after a ',' is an
                  // nlobs key petsc does not take (max_evaluations, the one it takes, is read).
                  const std::string rest = spec.rest();
                  if (const auto comma = rest.find(','); comma != std::string::npos) {
                    throw InvalidInput(
                        "engine spec 'petsc:" + printable(rest, 60) + "': unknown option(s) " +
                        quoted_excerpt(rest.substr(comma + 1)) +
                        " (petsc takes max_evaluations, and PETSc's options as :-key=value "
                        "after the type)");
                  }
                  PetscSnesOptions o;
                  try {
                    o = PetscSnesSolver::parse_name("petsc:" + rest);
                  } catch (const std::invalid_argument& e) {
                    throw InvalidInput(e.what());
                  }
                  return std::unique_ptr<Engine<Dynamic>>(
                      std::make_unique<PetscEngine>(std::move(o), std::move(solver)));
                },
            .without_common = kLibraryStops};
  }

 private:
  bool dense() const override { return false; }
  bool stop_by_throwing() const override { return true; }
  LibraryRun run_library(GuardedCalls& calls, Eigen::VectorXd& x) override {
    PetscSnesOptions o = library_options_;
    const long evaluations = budget();
    o.max_iterations = std::min<long>(evaluations, std::numeric_limits<int>::max());
    o.max_evaluations = evaluations;
    PetscPattern pattern;
    if (const SparseJacobianSource* source = calls.sparse(x)) {
      pattern.row_starts.assign(source->pattern->row_start.begin(),
                                source->pattern->row_start.end());
      pattern.columns.assign(source->pattern->columns.begin(), source->pattern->columns.end());
    } else if (x.size() > kMaxProblemDimension) {
      throw InvalidInput(label() + " needs F's sparse pattern at n = " + std::to_string(x.size()) +
                         " (" + calls.sparse_note() + ")");
    }
    PetscSnesSolver snes(
        static_cast<int>(x.size()), std::move(o),
        [&calls](const Eigen::VectorXd& v, Eigen::VectorXd& out) { calls.residual(v, out); },
        std::move(pattern));
    const PetscSnesResult r = snes.solve(x);
    std::string message = r.error.empty() ? r.reason_text : r.error;
    if (!r.reason_name.empty() && !r.success) {
      message = r.reason_name + (message.empty() ? "" : ": " + message);
    }
    return {r.status(),          r.iterations,       r.evaluations, r.jacobian_evaluations,
            r.linear_iterations, std::move(message), r.residual};
  }
  PetscSnesOptions library_options_;
};

}  // namespace

namespace {

// The one list of the reference engines: what add_reference_engines adds and
// is_reference_engine knows. petsc too in a build without PETSc: its set-up then refuses, saying
// so (invalid_input rows).
std::vector<EngineRegistry<Dynamic>::Entry> reference_entries() {
  return {KinsolEngine::entry(), MinpackEngine::entry(), GslEngine::entry(), PetscEngine::entry()};
}

}  // namespace

void add_reference_engines(EngineRegistry<Dynamic>& registry) {
  for (auto& e : reference_entries()) {
    if (!registry.has_entry(e.name)) registry.add(std::move(e), "built-in");
  }
}

bool is_reference_engine(std::string_view spec) {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const auto& e : reference_entries()) out.push_back(e.name);
    return out;
  }();
  const std::string_view name = spec.substr(0, spec.find(':'));
  return std::find(names.begin(), names.end(), name) != names.end();
}

void register_reference_engines() {
  static std::once_flag once;
  std::call_once(once, [] { add_reference_engines(EngineRegistry<Dynamic>::global()); });
}

}  // namespace nlobs::reference
