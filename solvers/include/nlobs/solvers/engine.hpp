#pragma once
// The one call shape every engine shares:  Summary s = engine.solve(problem, x);
// x holds the initial guess on entry and the engine's answer on return.
#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>

#include "nlobs/solvers/box_bounds.hpp"
#include "nlobs/solvers/library_sizes.hpp"
#include "nlobs/solvers/problem.hpp"
#include "nlobs/solvers/scaling.hpp"
#include "nlobs/solvers/stop_criteria.hpp"
#include "nlobs/solvers/summary.hpp"

namespace nlobs {

namespace detail {
// "newton, dogleg, …": the registered engines that accept bounds (strict: strict ones), asked of
// the engines themselves; defined with the registry, in the library.
std::string engines_taking_bounds(bool strict);
// "newton, dogleg, …, kinsol": the registered engines that accept a scaling, likewise.
std::string engines_taking_scaling();
}  // namespace detail

// One completed iteration as an iteration callback sees it: what the trace records (before a
// scaled solve maps the trace back), x not copied (valid during the call only).
struct IterationRecord {
  int iteration;     // 1, 2, … (Ceres: 0 for its starting point; NLopt: the evaluation's count)
  double step_norm;  // ‖x_k − x_{k−1}‖∞ (Ceres: its ‖Δx‖₂)
  // ‖F‖∞ where the engine last evaluated it: at x_k for the Newton-type engines; the step for
  // Picard (F(x_{k−1}) = x_k − x_{k−1}); at the point extrapolated from for aitken, steffensen,
  // anderson; Ceres: ‖F‖₂ = √(2 cost); NaN where there is no F (NLopt minimising f).
  double residual_norm;
  Eigen::Ref<const Eigen::VectorXd> x;  // x_k, in the engine's variables (scaled under a scaling)
};

// What an iteration callback tells the engine (Ceres' CallbackReturnType).
enum class IterationDecision { kContinue, kStop };

// Called after every completed iteration of a solve, on the solving thread (Ceres'
// IterationCallback, PETSc's SNESMonitorSet): to watch progress, log, or end the solve. kStop ends
// it with Status::kStoppedByCallback at the current iterate, which is judged as any run cut short
// (usable when ‖F‖ meets the tolerance). An exception it throws leaves solve() as the user's F's
// would (auto: as a stage's; to cancel, return kStop). It is copied with the options (into each
// stage of auto, Newton's trust region): keep state by reference.
using IterationCallback = std::function<IterationDecision(const IterationRecord&)>;

struct SolverOptions {
  StopCriteria stop{};
  bool record_trace = false;  // fill Summary::trace (allocates; off in hot loops)
  // Empty: none. Every built-in engine calls it (auto through its stages); a user's engine does
  // when it reports its iterations through Engine::after_iteration.
  IterationCallback iteration_callback{};
};

template <int N = Dynamic>
class Engine {
 public:
  virtual ~Engine() = default;
  virtual std::string_view name() const = 0;
  // What reports call this engine: the spec it was made from ("anderson:m=3", set by
  // EngineRegistry::create), else name(). Observers built on an engine take their label from it.
  std::string label() const { return label_.empty() ? std::string(name()) : label_; }
  void set_label(std::string label) { label_ = std::move(label); }
  // Throws InvalidInput for a dimension mismatch or a non-finite initial guess. Every other
  // outcome, including a non-finite G value, is a Status in the returned Summary.
  virtual Summary solve(const FixedPointProblem<N>& problem, Vector<N>& x) = 0;

  // F(x) = 0 for F: Rⁿ → Rᵐ in the least-squares sense. Engines for square systems (the
  // fixed-point engines, Newton) accept m = n — through G(x) = x + F(x), built per call — and
  // refuse m ≠ n; the Ceres and NLopt engines override this for any m.
  virtual Summary solve_least_squares(const RootProblem<N, Dynamic>& problem, Vector<N>& x);

  // True for engines that solve m > n (Ceres, NLopt).
  virtual bool least_squares() const { return false; }
  // True for engines that converge only where G contracts (Picard and its accelerations):
  // an observer then chooses a gain Ψ that makes its fixed-point map contract.
  virtual bool needs_contraction() const { return false; }

  const SolverOptions& options() const { return options_; }
  // SolverOptions::record_trace for the solves that follow: how an observer records one solve's
  // trace (a window estimator's first window, for its convergence plot) on the engine it runs
  // every step, without a second engine. Engines holding inner engines (auto's stages, Newton's
  // trust region, DynamicSizeEngine) pass it on.
  void set_record_trace(bool on) {
    options_.record_trace = on;
    on_set_record_trace(on);
  }
  // Sets StopCriteria::max_evaluations (≥ 1) for the solves that follow: how a polyalgorithm
  // hands each stage what the earlier ones left. An engine that runs other engines passes it on
  // (on_limit_evaluations).
  void limit_evaluations(int max_evaluations) {
    if (max_evaluations < 1) {
      throw InvalidInput(std::string(name()) + ": an evaluation budget must be >= 1");
    }
    options_.stop.max_evaluations = max_evaluations;
    on_limit_evaluations(max_evaluations);
  }

  // Box bounds lower ≤ x ≤ upper for the solves that follow (an empty side: no bound; ±inf
  // entries: no bound on that component). An engine that accepts them keeps every point where it
  // evaluates G inside the box, finite-difference points included, and refuses (InvalidInput) a
  // start outside it; the Newton-type engines project their steps (docs/solvers.md, "Bounds"),
  // Ceres and NLopt pass the box to their libraries. The others throw InvalidInput here, as do
  // bounds with lower > upper, NaN, lower = +inf or upper = −inf. Empty bounds remove the box.
  virtual bool accepts_bounds() const { return false; }
  // Strict sides (BoxBounds::strict_lower/strict_upper: lower < x): the Newton-type engines stop
  // a step that would reach one at a fraction of the way (nlobs/solvers/box_bounds.hpp) and never
  // evaluate G on it. An engine must say so: the others (Ceres and NLopt, whose boxes are closed,
  // and any plugin that does not override this) refuse them at set_bounds.
  virtual bool accepts_strict_bounds() const { return false; }
  void set_bounds(BoxBounds bounds) {
    if (!bounds.empty() && !accepts_bounds()) {
      throw InvalidInput(std::string(name()) + " does not accept bounds; engines that do: " +
                         detail::engines_taking_bounds(false));
    }
    if (scaled_solve_running_) {
      throw InvalidInput(std::string(name()) + ": set_bounds during a scaled solve");
    }
    detail::validate_box(name(), bounds);
    if (bounds.any_strict() && !accepts_strict_bounds()) {
      throw InvalidInput(
          std::string(name()) + " keeps x in a closed box only; engines that take strict bounds: " +
          detail::engines_taking_bounds(true) + " (auto when every stage is one of them)");
    }
    BoxBounds previous = std::move(bounds_);
    bounds_ = std::move(bounds);
    try {
      on_set_bounds();
    } catch (...) {  // a box the engine's library refuses: the engine keeps the one it had
      bounds_ = std::move(previous);
      throw;
    }
  }
  const BoxBounds& bounds() const { return bounds_; }

  // KINSOL's scaling for the solves that follow (nlobs/solvers/scaling.hpp: the engine works in
  // x̃ = D_u x on D_f F; its tolerances and Summary norms are the scaled ones). Accepted by the
  // Newton-type engines (newton, dogleg, levenberg-marquardt, broyden, pseudo-transient, auto)
  // and kinsol, which hands it to KINSOL; the others throw InvalidInput here, as do entries that
  // are not finite and > 0. A scale of another size than the problem's is refused by solve(). Empty
  // scales remove the scaling.
  virtual bool accepts_scaling() const { return false; }
  // Whether solve() takes the sparse path (J assembled sparse, steps by the linear-solver layer)
  // for a problem that carries a sparse Jacobian, declared or detected: newton with a line search
  // or full steps, pseudo-transient, levenberg-marquardt (the normal equations by CHOLMOD) and
  // broyden (limited memory), under a scaling too — not with linear_solver = "dense". The others
  // build and factor a dense n×n J (auto skips them on a large sparse problem).
  virtual bool has_sparse_path() const { return false; }
  void set_scaling(Scaling scaling) {
    if (scaled_solve_running_) {
      throw InvalidInput(std::string(name()) + ": set_scaling during a scaled solve");
    }
    if (!scaling.empty() && !accepts_scaling()) {
      throw InvalidInput(std::string(name()) + " does not accept a scaling; engines that do: " +
                         detail::engines_taking_scaling());
    }
    detail::validate_scaling(name(), scaling);
    Scaling previous = std::move(scaling_);
    scaling_ = std::move(scaling);
    try {
      on_set_scaling();
    } catch (...) {  // a stage that refuses it: the engine keeps the one it had
      scaling_ = std::move(previous);
      throw;
    }
  }
  const Scaling& scaling() const { return scaling_; }

 protected:
  explicit Engine(SolverOptions options) : options_(std::move(options)) { validate(options_.stop); }
  // What an engine does after each completed iteration (step ‖Δx‖∞, residual ‖F‖∞, iterate x):
  // the trace entry when record_trace is set, then the iteration callback; its kStop sets
  // `status` to kStoppedByCallback unless something else already ends the run. No allocation
  // without a trace; the work is out of line, so that a loop without either costs one test
  // (Picard at n = 5: +2.7 % instructions inline, none out of line; callgrind).
  void after_iteration(Summary& summary, std::optional<Status>& status, int iteration, double step,
                       double residual, const Vector<N>& x) const {
    if (options_.record_trace || options_.iteration_callback) [[unlikely]] {
      report_iteration(summary, status, iteration, step, residual, x);
    }
  }
  // Engines holding inner engines (DynamicSizeEngine, Newton's trust region) forward the limit.
  virtual void on_limit_evaluations(int /*max_evaluations*/) {}
  // ... and set_record_trace (auto's stages too).
  virtual void on_set_record_trace(bool /*on*/) {}
  // Engines holding inner engines or a library's own copy of the box (Ceres, NLopt) take it here.
  virtual void on_set_bounds() {}
  // Engines holding inner engines (auto's stages, Newton's trust region, DynamicSizeEngine) pass
  // the scaling on; the others apply it themselves through solve_scaled.
  virtual void on_set_scaling() {}
  // For an engine that applies a scaling itself, first thing in solve(): with a scaling set (and
  // not already inside this call), checks x and the box in the problem's terms, solves the
  // scaled problem by self.Self::solve — the engine's own solve, called non-virtually — with the
  // box in scaled variables, and returns its summary with x and the trace's points in the
  // problem's variables (inside its box); nullopt otherwise. A scaled solve allocates (the scaled
  // problem, the box), at fixed N too: once per solve, not per evaluation.
  //   if (auto scaled = this->solve_scaled(*this, problem, x)) return std::move(*scaled);
  template <typename Self>
  std::optional<Summary> solve_scaled(Self& self, const FixedPointProblem<N>& problem,
                                      Vector<N>& x);
  SolverOptions options_;
  BoxBounds bounds_;
  Scaling scaling_;

 private:
  [[gnu::noinline]] void report_iteration(Summary& summary, std::optional<Status>& status,
                                          int iteration, double step, double residual,
                                          const Vector<N>& x) const {
    if (options_.record_trace) summary.trace.push_back({iteration, step, residual, x});
    if (options_.iteration_callback &&
        options_.iteration_callback(IterationRecord{iteration, step, residual, x}) ==
            IterationDecision::kStop &&
        !status) {
      status = Status::kStoppedByCallback;
    }
  }
  bool scaled_solve_running_ = false;
  std::string label_;
};

template <int N>
Summary Engine<N>::solve_least_squares(const RootProblem<N, Dynamic>& problem, Vector<N>& x) {
  if (problem.residual_size() != problem.size()) {
    std::ostringstream os;
    os << name() << " solves square systems only: F maps R^" << problem.size() << " to R^"
       << problem.residual_size() << "; use a least-squares engine (ceres, nlopt)";
    throw InvalidInput(os.str());
  }
  const auto g = [&problem](const Vector<N>& v, Vector<N>& out) {
    Vector<Dynamic> f(problem.residual_size());
    problem.evaluate(v, f);
    out = v + f;
  };
  // F itself too (FixedPointProblem::residual): the engines need not form G(x) − x.
  const auto f = [&problem](const Vector<N>& v, Vector<N>& out) {
    Vector<Dynamic> value(problem.residual_size());
    problem.evaluate(v, value);
    out = value;
  };
  if (!problem.has_jacobian()) {
    return solve(FixedPointProblem<N>::from_map(g, problem.size()).with_residual(f), x);
  }
  const auto df = [&problem](const Vector<N>& v, Matrix<N, N>& j) {
    Matrix<Dynamic, N> d(problem.residual_size(), problem.size());
    problem.jacobian(v, d);
    j = d;
  };
  const auto dg = [&problem](const Vector<N>& v, Matrix<N, N>& j) {
    Matrix<Dynamic, N> d(problem.residual_size(), problem.size());
    problem.jacobian(v, d);
    j = d;
    j.diagonal().array() += 1.0;
  };
  return solve(FixedPointProblem<N>::with_jacobian(g, dg, problem.size(), problem.jacobian_source())
                   .with_residual(f, df),
               x);
}

// For batch drivers (CLI, benchmarks): invalid input becomes status invalid_input with the
// message in Summary::message instead of an exception.
template <int N>
Summary solve_or_report(Engine<N>& engine, const FixedPointProblem<N>& problem, Vector<N>& x) {
  try {
    return engine.solve(problem, x);
  } catch (const InvalidInput& e) {
    Summary s;
    s.engine = engine.name();
    s.status = Status::kInvalidInput;
    s.message = e.what();
    return s;
  }
}

namespace detail {

// The error-bound criterion needs L; only Picard steps can estimate it (StopMonitor).
inline void require_lipschitz_for_error_bound(std::string_view engine, const StopCriteria& c) {
  if (c.error_tolerance && !c.lipschitz_constant) {
    std::ostringstream os;
    os << engine << ": StopCriteria::error_tolerance = " << *c.error_tolerance
       << " needs StopCriteria::lipschitz_constant (only the picard engine estimates L from its "
          "steps)";
    throw InvalidInput(os.str());
  }
}

template <int N>
void check_initial_guess(std::string_view engine, Index dimension, const Vector<N>& x) {
  if (x.size() != dimension) {
    std::ostringstream os;
    os << engine << ": initial guess has size " << x.size() << " but the problem has dimension "
       << dimension;
    throw InvalidInput(os.str());
  }
  for (Index i = 0; i < x.size(); ++i) {
    if (!std::isfinite(x[i])) {
      std::ostringstream os;
      os << engine << ": initial guess x0[" << i << "] = " << x[i] << " is not finite";
      throw InvalidInput(os.str());
    }
  }
}

template <int N>
void check_initial_guess(std::string_view engine, const FixedPointProblem<N>& problem,
                         const Vector<N>& x) {
  check_initial_guess<N>(engine, problem.size(), x);
}

}  // namespace detail

template <int N>
template <typename Self>
std::optional<Summary> Engine<N>::solve_scaled(Self& self, const FixedPointProblem<N>& problem,
                                               Vector<N>& x) {
  if (scaling_.empty() || scaled_solve_running_) return std::nullopt;
  // Checked in the problem's own terms before anything is scaled.
  detail::check_initial_guess<N>(name(), problem.size(), x);
  detail::require_inside_box<N>(name(), bounds_, x);
  Vector<N> du, df;
  detail::scaling_for<N>(name(), scaling_, problem.size(), du, df);
  Vector<N> xs = x.cwiseProduct(du);
  if (!xs.allFinite()) {
    throw InvalidInput(std::string(name()) +
                       ": u_scale times the initial guess overflows (choose D_u x of order 1)");
  }
  const BoxBounds original = bounds_;
  const FixedPointProblem<N> scaled = detail::scaled_problem<N>(problem, du, df, original);
  bounds_ = detail::scaled_bounds(original, scaling_.u_scale);  // the engine's box, in x̃
  scaled_solve_running_ = true;
  struct Restore {
    Engine* engine;
    const BoxBounds* original;
    ~Restore() {
      engine->bounds_ = *original;
      engine->scaled_solve_running_ = false;
    }
  } restore{this, &original};
  Summary s = self.Self::solve(scaled, xs);
  // Back in the problem's variables, as the scaled map evaluated it: inside the box. (Component
  // by component: GCC 12 warns of Eigen's packet loads at N = 1.)
  detail::Box<N> box;
  box.set(original, du.size());
  const auto back = [&](double v, Index i) { return box.clamp(i, v / du[i]); };
  for (Index i = 0; i < x.size(); ++i) x[i] = back(xs[i], i);
  for (TraceEntry& t : s.trace) {
    if (t.x.size() != du.size()) continue;
    for (Index i = 0; i < t.x.size(); ++i) t.x[i] = back(t.x[i], i);
  }
  s.point_finite = x.allFinite();  // D_u⁻¹ x̃ may overflow where x̃ did not
  return s;
}

// Compiled once in the library for its sizes (nlobs/solvers/library_sizes.hpp).
#define NLOBS_EXTERN_ENGINE(n) extern template class Engine<n>;
NLOBS_FOR_EACH_LIBRARY_SIZE(NLOBS_EXTERN_ENGINE)
#undef NLOBS_EXTERN_ENGINE

}  // namespace nlobs
