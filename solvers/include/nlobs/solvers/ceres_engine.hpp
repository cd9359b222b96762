#pragma once
// Least squares with Ceres: min ½‖F(x)‖₂² for F: Rⁿ → Rᵐ (any m; m ≥ n is the usual case),
// Levenberg–Marquardt or dogleg, optional box bounds. A FixedPointProblem is solved as the
// square system F = G − x.
//
// Two back ends behind one engine:
//   * ceres::TinySolver — Levenberg–Marquardt with everything on the stack, for fixed sizes
//     without bounds: no per-solve set-up at all (chosen automatically when it applies);
//   * ceres::Solve on a ceres::Problem prepared once per (n, m) and reused by every solve —
//     dogleg, bounds, dynamic sizes, and Ceres' full report.
// Derivatives: the problem's Jacobian (user-supplied, or ceres::Jet AD when the function is
// generic in its scalar) or finite differences otherwise.
#include <ceres/ceres.h>
#include <ceres/tiny_solver.h>

#include <cmath>
#include <exception>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "nlobs/solvers/box_bounds.hpp"
#include "nlobs/solvers/engine.hpp"
#include "nlobs/solvers/engine_spec.hpp"
#include "nlobs/solvers/library_sizes.hpp"
#include "nlobs/solvers/residual_source.hpp"

namespace nlobs {

struct CeresOptions {
  enum class Method { kLevenbergMarquardt, kDogleg };
  enum class Backend {
    kAuto,        // TinySolver for fixed N with LM, no bounds, no iteration callback, else Solver
    kTinySolver,  // fixed N only; LM only; no bounds
    kSolver,      // ceres::Solve on a prepared ceres::Problem
  };
  Method method = Method::kLevenbergMarquardt;
  Backend backend = Backend::kAuto;
  // Box bounds on x; empty = none; ±inf allowed per component.
  Eigen::VectorXd lower_bounds{}, upper_bounds{};
  // Ceres' relative cost-change and gradient tolerances (the step tolerance comes from
  // StopCriteria::step_tolerance as Ceres' parameter_tolerance).
  double function_tolerance = 1e-10;
  double gradient_tolerance = 1e-12;
  // Solver back end only (TinySolver always scales). Defaults chosen by measurement on the
  // MGH suite (docs/solvers.md): without Jacobi scaling and with non-monotonic steps, LM
  // solves 43 of 57 pairs instead of 40, with a third of the evaluations.
  bool jacobi_scaling = false;
  bool nonmonotonic_steps = true;
  FiniteDifference finite_difference = FiniteDifference::kCentral;  // problems without ∂F

  // Throws InvalidInput naming the field, its value and the requirement (options_validation.hpp);
  // the engine adds what depends on its size (TinySolver needs a compile-time one).
  void validate() const;
  // The engine as the registry lists it, the spec keys (field names; older ones as aliases; the
  // method as a bare word) and their reading over these values (src/options/ceres_options.cpp).
  static EngineDescription describe();
  void read(EngineSpecReader& spec);
};

template <int N = Dynamic>
class CeresEngine : public Engine<N> {
 public:
  using Options = CeresOptions;

  explicit CeresEngine(CeresOptions ceres = {}, SolverOptions options = {})
      : Engine<N>(std::move(options)), ceres_(std::move(ceres)) {
    detail::require_lipschitz_for_error_bound(name(), this->options_.stop);
    ceres_.validate();
    if (N == Dynamic && ceres_.backend == CeresOptions::Backend::kTinySolver) {
      throw InvalidInput("CeresOptions::backend = kTinySolver needs a compile-time size");
    }
    if (this->options_.iteration_callback && ceres_.backend == CeresOptions::Backend::kTinySolver) {
      throw InvalidInput(
          "CeresOptions::backend = kTinySolver has no iteration callback "
          "(SolverOptions::iteration_callback): use kSolver or kAuto");
    }
    this->bounds_ = {ceres_.lower_bounds, ceres_.upper_bounds};
  }

  std::string_view name() const override { return "ceres"; }
  const CeresOptions& ceres_options() const { return ceres_; }
  // Every back end but TinySolver (set_bounds replaces CeresOptions' bounds).
  bool accepts_bounds() const override {
    return ceres_.backend != CeresOptions::Backend::kTinySolver;
  }
  bool accepts_strict_bounds() const override { return false; }  // Ceres' box is closed
  // Which back end solve() uses (for a fixed-size problem).
  bool uses_tiny_solver() const {
    return N != Dynamic && ceres_.backend != CeresOptions::Backend::kSolver &&
           !this->options_.iteration_callback &&
           ceres_.method == CeresOptions::Method::kLevenbergMarquardt &&
           ceres_.lower_bounds.size() == 0 && ceres_.upper_bounds.size() == 0;
  }
  // Ceres' own summary of the last solve on the Solver back end (FullReport() for text).
  const ceres::Solver::Summary& ceres_summary() const { return ceres_summary_; }

  // Square system F = G − x.
  Summary solve(const FixedPointProblem<N>& problem, Vector<N>& x) override;

  bool least_squares() const override { return true; }
  Summary solve_least_squares(const RootProblem<N, Dynamic>& problem, Vector<N>& x) override;

  // Least squares on F: Rⁿ → Rᵐ.
  template <int M>
  Summary solve(const RootProblem<N, M>& problem, Vector<N>& x) {
    detail::check_initial_guess(name(), problem.size(), x);
    return run<M>(detail::ResidualSource<N, M>(problem), x);
  }

 private:
  template <int M>
  struct Workspace {
    Vector<N> x = zero_vector<N>(), prev = zero_vector<N>();
    Vector<M> f = zero_vector<M>(), fp = zero_vector<M>(), fm = zero_vector<M>();
    Matrix<M, N> j;
    FiniteDifferenceWorkspace<N> fd;
    int evaluations = 0, jacobians = 0;
    bool non_finite = false, jacobian_failed = false, budget_exhausted = false, have_prev = false;
    double last_step = 0.0;
    std::exception_ptr thrown;  // what a user's F or Jacobian threw inside ceres::Solve

    void resize(Index n, Index m) {
      x.resize(n), prev.resize(n), f.resize(m), fp.resize(m), fm.resize(m), j.resize(m, n);
      fd.resize(n);
    }
  };

  template <int M>
  Summary run(const detail::ResidualSource<N, M>& source, Vector<N>& x) {
    detail::require_inside_box<N>("ceres", ceres_.lower_bounds, ceres_.upper_bounds, x);
    if constexpr (N != Dynamic) {
      if (uses_tiny_solver()) return run_tiny<M>(source, x);
    }
    return run_solver<M>(source, x);
  }

  // F (and ∂F when `jacobian` is non-null, column-major m×n) at x; false when non-finite
  // or when the evaluation budget is spent.
  template <int M>
  bool evaluate(const detail::ResidualSource<N, M>& source, Workspace<M>& w, const double* x,
                double* residuals, double* jacobian, bool row_major) const {
    if (w.evaluations >= this->options_.stop.max_evaluations) {
      w.budget_exhausted = true;
      return false;
    }
    const Index n = source.size(), m = source.residual_size();
    w.x = Eigen::Map<const Vector<N>>(x, n);
    source.residual(w.x, w.f);
    ++w.evaluations;
    if (!w.f.allFinite()) {
      w.non_finite = true;
      w.jacobian_failed = w.jacobian_failed || jacobian != nullptr;
      return false;
    }
    Eigen::Map<Vector<M>>(residuals, m) = w.f;
    if (jacobian != nullptr) {
      w.evaluations += detail::residual_jacobian(source, w.x, w.f, w.j, ceres_.finite_difference,
                                                 w.fd, w.fp, w.fm);
      ++w.jacobians;
      if (!w.j.allFinite()) {
        w.non_finite = w.jacobian_failed = true;
        return false;
      }
      if (row_major) {
        Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
            jacobian, m, n) = w.j;
      } else {
        Eigen::Map<Matrix<M, N>>(jacobian, m, n) = w.j;
      }
      // Jacobians are formed at accepted iterates: track the step between them.
      if (w.have_prev) w.last_step = (w.x - w.prev).template lpNorm<Eigen::Infinity>();
      w.prev = w.x;
      w.have_prev = true;
    }
    return true;
  }

  template <int M>
  Summary finish(const detail::ResidualSource<N, M>& source, Workspace<M>& w, Vector<N>& x,
                 Status status, int iterations) const {
    Summary s;
    s.engine = name();
    // A non-finite value at a trial point is a rejected step (Ceres recovers); at a point where
    // the Jacobian is formed, nothing the solver concludes afterwards can be trusted.
    // A stop the user's callback asked for is theirs, whatever trial points Ceres rejected.
    if (w.jacobian_failed ||
        (w.non_finite && status != Status::kConverged && status != Status::kStoppedByCallback)) {
      status = Status::kNonFinite;
    }
    if (w.budget_exhausted) status = Status::kMaxEvaluations;  // cut short, whatever it claims
    source.residual(x, w.f);  // residual at the returned point, counted
    ++w.evaluations;
    s.status = status;
    s.iterations = iterations;
    s.function_evaluations = w.evaluations;
    s.jacobian_evaluations = w.jacobians;
    s.step_norm = w.last_step;
    s.residual_norm = w.f.allFinite() ? w.f.template lpNorm<Eigen::Infinity>()
                                      : std::numeric_limits<double>::infinity();
    // An overdetermined F keeps a residual at its least-squares point.
    s.record_answer(x, this->options_.stop, source.residual_size() > source.size());
    return s;
  }

// GCC cannot see that TinySolver's cost is set by the (now pre-checked) first evaluation
// (clang has no such warning, and would warn about the unknown group).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
  // TinySolver is a header template compiled here, holding nothing but Eigen values: a user's
  // exception unwinds through it to the caller like through any of our engines.
  template <int M>
  Summary run_tiny(const detail::ResidualSource<N, M>& source, Vector<N>& x) {
    Workspace<M> w;  // fixed sizes: on the stack, nothing allocated
    w.resize(source.size(), source.residual_size());
    // TinySolver does not check its first evaluation (it would read an unset cost): do it here.
    source.residual(x, w.f);
    ++w.evaluations;
    if (!w.f.allFinite()) {
      w.non_finite = true;
      return finish<M>(source, w, x, Status::kNonFinite, 0);
    }
    const StopCriteria& stop = this->options_.stop;
    ceres::TinySolver<TinyCost<M>> solver;
    solver.options.max_num_iterations = stop.max_iterations;
    solver.options.gradient_tolerance = ceres_.gradient_tolerance;
    solver.options.parameter_tolerance = stop.step_tolerance.value_or(0.0);
    // TinySolver's cost-change test is absolute; keep it only for an exactly zero change.
    solver.options.function_tolerance = std::numeric_limits<double>::min();
    const double ftol = stop.residual_tolerance.value_or(1e-15);
    solver.options.cost_threshold = 0.5 * ftol * ftol;  // ‖F‖₂ ≤ tol ⇒ ‖F‖∞ ≤ tol
    Vector<N> p = x;
    const auto& summary = solver.Solve(TinyCost<M>{this, &source, &w}, &p);
    Status status = Status::kConverged;
    if (summary.status == ceres::TinySolver<TinyCost<M>>::HIT_MAX_ITERATIONS) {
      status = Status::kMaxIterations;
    }
    if (p.allFinite()) x = p;
    return finish<M>(source, w, x, status, summary.iterations);
  }
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

  // The cost functor TinySolver wants: sizes as enums, column-major Jacobian.
  template <int M>
  struct TinyCost {
    using Scalar = double;
    enum { NUM_RESIDUALS = M, NUM_PARAMETERS = N };
    const CeresEngine* engine;
    const detail::ResidualSource<N, M>* source;
    Workspace<M>* w;
    bool operator()(const double* p, double* r, double* j) const {
      return engine->evaluate(*source, *w, p, r, j, /*row_major=*/false);
    }
    int NumResiduals() const { return static_cast<int>(source->residual_size()); }
    int NumParameters() const { return N; }
  };

  // Aborts the Solver when the residual target or the evaluation budget is reached, or when a
  // user's function threw.
  struct Monitor : ceres::IterationCallback {
    double cost_target = 0.0;
    const bool* budget = nullptr;
    std::exception_ptr* thrown = nullptr;
    bool reached = false;
    // SolverOptions::iteration_callback, given x_k (update_state_every_iteration keeps the
    // parameter block current while there is one).
    const nlobs::IterationCallback* user = nullptr;
    const double* params = nullptr;
    int n = 0;
    bool stopped_by_user = false;
    ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
      if (*thrown) return ceres::SOLVER_ABORT;
      if (user != nullptr && *user) {
        try {
          const IterationRecord record{s.iteration, s.step_norm, std::sqrt(2.0 * s.cost),
                                       Eigen::Map<const Eigen::VectorXd>(params, n)};
          if ((*user)(record) == IterationDecision::kStop) {
            // Not SOLVER_ABORT: on USER_FAILURE Ceres puts x0 back into the parameter block; on
            // USER_SUCCESS it keeps the iterate the callback saw.
            stopped_by_user = true;
            return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
          }
        } catch (...) {  // rethrown once Solve has returned, as the user's F's would be
          *thrown = std::current_exception();
          return ceres::SOLVER_ABORT;
        }
      }
      if (s.cost <= cost_target) {
        reached = true;
        return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
      }
      return *budget ? ceres::SOLVER_ABORT : ceres::SOLVER_CONTINUE;
    }
  };

  class CostAdapter final : public ceres::CostFunction {
   public:
    CostAdapter(int n, int m) {
      set_num_residuals(m);
      mutable_parameter_block_sizes()->push_back(n);
    }
    std::function<bool(const double*, double*, double*)> callback;
    bool Evaluate(double const* const* p, double* r, double** j) const override {
      return callback(p[0], r, j != nullptr ? j[0] : nullptr);
    }
  };

  template <int M>
  Summary run_solver(const detail::ResidualSource<N, M>& source, Vector<N>& x) {
    const int n = static_cast<int>(source.size()), m = static_cast<int>(source.residual_size());
    if (!problem_ || prepared_n_ != n || prepared_m_ != m) prepare(n, m);
    Workspace<M> w;
    w.resize(n, m);
    // Ceres does not promise to survive an exception unwinding through ceres::Solve (it holds
    // the prepared Problem's state, reused by the next solve): a user's exception, of any type,
    // fails this evaluation and every later one (no more user calls), the Monitor aborts, and
    // the exception is rethrown unchanged once Solve has returned.
    cost_->callback = [this, &source, &w](const double* p, double* r, double* j) {
      if (w.thrown) return false;
      try {
        return evaluate(source, w, p, r, j, /*row_major=*/true);
      } catch (...) {
        w.thrown = std::current_exception();
        return false;
      }
    };
    Eigen::Map<Vector<N>>(params_.data(), n) = x;
    const StopCriteria& stop = this->options_.stop;
    ceres::Solver::Options o;
    o.minimizer_type = ceres::TRUST_REGION;
    o.trust_region_strategy_type =
        ceres_.method == CeresOptions::Method::kDogleg ? ceres::DOGLEG : ceres::LEVENBERG_MARQUARDT;
    o.linear_solver_type = ceres::DENSE_QR;
    o.max_num_iterations = stop.max_iterations;
    o.function_tolerance = ceres_.function_tolerance;
    o.gradient_tolerance = ceres_.gradient_tolerance;
    o.parameter_tolerance = stop.step_tolerance.value_or(0.0);
    o.logging_type = ceres::SILENT;
    o.jacobi_scaling = ceres_.jacobi_scaling;
    o.use_nonmonotonic_steps = ceres_.nonmonotonic_steps;
    o.num_threads = 1;
    Monitor monitor;
    const double ftol = stop.residual_tolerance.value_or(1e-15);
    monitor.cost_target = 0.5 * ftol * ftol;
    monitor.budget = &w.budget_exhausted;
    monitor.thrown = &w.thrown;
    monitor.user = &this->options_.iteration_callback;
    monitor.params = params_.data();
    monitor.n = n;
    o.callbacks.push_back(&monitor);
    o.update_state_every_iteration = static_cast<bool>(this->options_.iteration_callback);
    ceres::Solve(o, problem_.get(), &ceres_summary_);
    cost_->callback = nullptr;
    if (w.thrown) std::rethrow_exception(w.thrown);

    Status status = Status::kSolverFailure;
    switch (ceres_summary_.termination_type) {
      case ceres::CONVERGENCE:
        status = Status::kConverged;
        break;
      case ceres::USER_SUCCESS:
        status = monitor.stopped_by_user ? Status::kStoppedByCallback : Status::kConverged;
        break;
      case ceres::NO_CONVERGENCE:
        status = Status::kMaxIterations;
        break;
      case ceres::USER_FAILURE:
      case ceres::FAILURE:
        status = Status::kSolverFailure;
        break;
    }
    const Vector<N> p = Eigen::Map<const Vector<N>>(params_.data(), n);
    if (p.allFinite()) x = p;
    Summary s = finish<M>(source, w, x, status, static_cast<int>(ceres_summary_.iterations.size()));
    if (s.status == Status::kSolverFailure) s.message = ceres_summary_.message;
    return s;
  }

  void on_set_bounds() override {
    ceres_.lower_bounds = this->bounds_.lower;
    ceres_.upper_bounds = this->bounds_.upper;
    problem_.reset();  // prepared again, with the new box, by the next solve
  }

  void prepare(int n, int m) {
    cost_ = std::make_unique<CostAdapter>(n, m);
    params_.assign(static_cast<size_t>(n), 0.0);
    ceres::Problem::Options po;
    po.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    problem_ = std::make_unique<ceres::Problem>(po);
    problem_->AddResidualBlock(cost_.get(), nullptr, params_.data());
    for (int i = 0; i < ceres_.lower_bounds.size(); ++i) {
      if (std::isfinite(ceres_.lower_bounds[i])) {
        problem_->SetParameterLowerBound(params_.data(), i, ceres_.lower_bounds[i]);
      }
    }
    for (int i = 0; i < ceres_.upper_bounds.size(); ++i) {
      if (std::isfinite(ceres_.upper_bounds[i])) {
        problem_->SetParameterUpperBound(params_.data(), i, ceres_.upper_bounds[i]);
      }
    }
    prepared_n_ = n;
    prepared_m_ = m;
  }

  CeresOptions ceres_;
  std::unique_ptr<CostAdapter> cost_;
  std::unique_ptr<ceres::Problem> problem_;
  std::vector<double> params_;
  int prepared_n_ = -1, prepared_m_ = -1;
  ceres::Solver::Summary ceres_summary_;
};

// Out of the class body: GCC instantiates in-class (inline) bodies even of an extern template,
// to inline them, so only out-of-class bodies let a file that uses a library size (extern
// below) compile none of the engine.
template <int N>
Summary CeresEngine<N>::solve(const FixedPointProblem<N>& problem, Vector<N>& x) {
  detail::check_initial_guess(name(), problem, x);
  Summary s = run<N>(detail::ResidualSource<N, N>(problem), x);
  if (const auto& l = this->options_.stop.lipschitz_constant) {  // F = G − x: [MGFF23]
    s.lipschitz_constant = l;
    s.error_bound = s.residual_norm / (1.0 - *l);
  }
  return s;
}

template <int N>
Summary CeresEngine<N>::solve_least_squares(const RootProblem<N, Dynamic>& problem, Vector<N>& x) {
  return solve<Dynamic>(problem, x);
}

#define NLOBS_EXTERN_CERES_ENGINE(n) extern template class CeresEngine<n>;
NLOBS_FOR_EACH_LIBRARY_SIZE(NLOBS_EXTERN_CERES_ENGINE)
#undef NLOBS_EXTERN_CERES_ENGINE

}  // namespace nlobs
