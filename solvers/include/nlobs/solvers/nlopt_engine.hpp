#pragma once
// Bounded minimisation with NLopt. Objectives: a scalar ObjectiveProblem (minimize()), or
// ½‖F(x)‖₂² for a RootProblem or a FixedPointProblem (F = G − x) through solve(). Any NLopt
// algorithm by name ("LN_BOBYQA", "LN_COBYLA", "LD_SLSQP", "LD_LBFGS", "GN_DIRECT_L", ...);
// gradient-based ones (xD_*) get ∇(½‖F‖²) = Jᵀ F from the problem's Jacobian (AD or user) or
// from finite differences. The nlopt::opt object is built once per dimension and reused by
// every solve, so repeated small bounded problems (the MVT observer's β) pay no set-up.
#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <nlopt.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "nlobs/solvers/box_bounds.hpp"
#include "nlobs/solvers/engine.hpp"
#include "nlobs/solvers/engine_spec.hpp"
#include "nlobs/solvers/library_sizes.hpp"
#include "nlobs/solvers/objective_problem.hpp"
#include "nlobs/solvers/residual_source.hpp"

namespace nlobs {

struct NloptOptions {
  std::string algorithm = "LN_BOBYQA";
  // Box bounds; empty = unbounded; ±inf allowed per component except for global (G*)
  // algorithms, which need a finite box.
  Eigen::VectorXd lower_bounds{}, upper_bounds{};
  // minimize(): stop once the objective is ≤ this (solve() uses ½ residual_tolerance²).
  std::optional<double> stop_value{};
  double relative_step_tolerance = 0.0;  // NLopt xtol_rel; 0 = off
  std::optional<double> initial_step{};  // first step of derivative-free algorithms
  FiniteDifference finite_difference = FiniteDifference::kCentral;

  // Throws InvalidInput naming the field, its value and the requirement (options_validation.hpp):
  // an algorithm NLopt does not have, a malformed box, a global (G*) algorithm without a finite
  // box, a step or tolerance out of range.
  void validate() const;
  // The engine as the registry lists it, the spec keys (field names; older ones as aliases; the
  // algorithm as a bare word) and their reading over these values (src/options/nlopt_options.cpp).
  static EngineDescription describe();
  void read(EngineSpecReader& spec);
};

// NLopt's algorithm names ("LN_BOBYQA", ...), all of them.
std::vector<std::string> nlopt_algorithm_names();

template <int N = Dynamic>
class NloptEngine : public Engine<N> {
 public:
  using Options = NloptOptions;

  explicit NloptEngine(NloptOptions nlopt = {}, SolverOptions options = {})
      : Engine<N>(std::move(options)), nlopt_(std::move(nlopt)) {
    detail::require_lipschitz_for_error_bound(name(), this->options_.stop);
    nlopt_.validate();
    // NLopt's enumerators are the positions in nlopt_algorithm_names() (validate() found it).
    const std::vector<std::string> names = nlopt_algorithm_names();
    algorithm_ = static_cast<nlopt_algorithm>(
        std::find(names.begin(), names.end(), nlopt_.algorithm) - names.begin());
    this->bounds_ = {nlopt_.lower_bounds, nlopt_.upper_bounds};
  }

  std::string_view name() const override { return "nlopt"; }
  const NloptOptions& nlopt_options() const { return nlopt_; }
  bool needs_gradient() const { return nlopt_.algorithm.size() > 1 && nlopt_.algorithm[1] == 'D'; }
  bool is_global() const { return !nlopt_.algorithm.empty() && nlopt_.algorithm[0] == 'G'; }
  // set_bounds replaces NloptOptions' bounds (a global algorithm still needs a finite box).
  bool accepts_bounds() const override { return true; }
  bool accepts_strict_bounds() const override { return false; }  // NLopt's box is closed

  // min ½‖G(x) − x‖₂².
  Summary solve(const FixedPointProblem<N>& problem, Vector<N>& x) override;
  bool least_squares() const override { return true; }
  Summary solve_least_squares(const RootProblem<N, Dynamic>& problem, Vector<N>& x) override;

  // min ½‖F(x)‖₂².
  template <int M>
  Summary solve(const RootProblem<N, M>& problem, Vector<N>& x) {
    detail::check_initial_guess(name(), problem.size(), x);
    return run_residual<M>(detail::ResidualSource<N, M>(problem), x);
  }
  // min f(x).
  Summary minimize(const ObjectiveProblem<N>& problem, Vector<N>& x);

 private:
  void on_set_bounds() override {
    NloptOptions bounded = nlopt_;  // a refused box leaves the options as they were
    bounded.lower_bounds = this->bounds_.lower;
    bounded.upper_bounds = this->bounds_.upper;
    bounded.validate();
    nlopt_ = std::move(bounded);
    prepared_n_ = -1;  // prepared again, with the new box, by the next solve
  }
  using ObjectiveThunk = double (*)(void*, const Vector<N>&, Vector<N>*);

  template <int M>
  struct ResidualContext {
    NloptEngine* engine;
    const detail::ResidualSource<N, M>* source;
    Vector<M> f, fp, fm;
    Matrix<M, N> j;
    FiniteDifferenceWorkspace<N> fd;
  };

  template <int M>
  Summary run_residual(const detail::ResidualSource<N, M>& source, Vector<N>& x) {
    const Index n = source.size(), m = source.residual_size();
    ResidualContext<M> ctx{
        this, &source, Vector<M>(m), Vector<M>(m), Vector<M>(m), Matrix<M, N>(m, n), {}};
    ctx.fd.resize(n);
    const std::optional<double>& ftol = this->options_.stop.residual_tolerance;
    const double stop = ftol ? 0.5 * *ftol * *ftol : -std::numeric_limits<double>::infinity();
    Summary s = run(
        x, stop,
        +[](void* data, const Vector<N>& at, Vector<N>* grad) {
          auto* c = static_cast<ResidualContext<M>*>(data);
          c->source->residual(at, c->f);
          ++c->engine->evaluations_;
          c->engine->report_evaluation(at, c->f.allFinite()
                                               ? c->f.template lpNorm<Eigen::Infinity>()
                                               : std::numeric_limits<double>::infinity());
          if (grad != nullptr) {
            c->engine->evaluations_ +=
                detail::residual_jacobian(*c->source, at, c->f, c->j,
                                          c->engine->nlopt_.finite_difference, c->fd, c->fp, c->fm);
            ++c->engine->jacobians_;
            grad->noalias() = c->j.transpose() * c->f;  // ∇ ½‖F‖² = Jᵀ F
          }
          return 0.5 * c->f.squaredNorm();
        },
        &ctx);
    source.residual(x, ctx.f);  // residual at the returned point, counted
    ++s.function_evaluations;
    s.residual_norm = ctx.f.allFinite() ? ctx.f.template lpNorm<Eigen::Infinity>()
                                        : std::numeric_limits<double>::infinity();
    s.record_answer(x, this->options_.stop, m > n);
    return s;
  }

  // Central or forward differences of a scalar objective.
  int scalar_gradient(const ObjectiveProblem<N>& p, const Vector<N>& x, double fx,
                      Vector<N>& grad) {
    Matrix<1, N> row(1, x.size());
    Vector<1> f0(fx), fp, fm;
    FiniteDifferenceWorkspace<N> work;
    work.resize(x.size());
    const int evals = finite_difference_jacobian<N, 1>(
        [&p](const Vector<N>& at, Vector<1>& out) { out[0] = p.evaluate(at); }, x, f0, row,
        nlopt_.finite_difference, work, fp, fm);
    grad = row.transpose();
    return evals;
  }

  // SolverOptions::iteration_callback after each evaluation of F (NLopt has no iterations of its
  // own): the evaluation's count, the distance from the point evaluated before, ‖F‖∞ (NaN when
  // minimising f). kStop stops NLopt (force_stop).
  void report_evaluation(const Vector<N>& at, double residual) {
    const IterationCallback& callback = this->options_.iteration_callback;
    if (!callback || stopped_by_user_) return;  // once it said stop, never again
    const double step =
        evaluations_ > 1 ? (at - last_reported_).template lpNorm<Eigen::Infinity>() : 0.0;
    if (callback(IterationRecord{evaluations_, step, residual, at}) == IterationDecision::kStop) {
      stopped_by_user_ = true;
      opt_->force_stop();
    }
    last_reported_ = at;
  }

  static double trampoline(unsigned n, const double* x, double* grad, void* data) {
    auto* self = static_cast<NloptEngine*>(data);
    self->x_ = Eigen::Map<const Vector<N>>(x, n);
    double f;
    // A user's F or Jacobian may throw anything. NLopt's C++ wrapper would catch it and report
    // only "nlopt failure" (and nothing may unwind through NLopt's C frames): keep it, stop NLopt,
    // and run() rethrows it once NLopt has returned.
    try {
      if (grad != nullptr) {
        f = self->thunk_(self->context_, self->x_, &self->grad_);
        Eigen::Map<Vector<N>>(grad, n) = self->grad_;
        if (!self->grad_.allFinite()) f = std::numeric_limits<double>::quiet_NaN();
      } else {
        f = self->thunk_(self->context_, self->x_, nullptr);
      }
    } catch (...) {
      self->thrown_ = std::current_exception();
      self->opt_->force_stop();
      return std::numeric_limits<double>::max();
    }
    if (!std::isfinite(f)) {
      self->non_finite_ = true;
      self->opt_->force_stop();  // NLopt cannot recover from NaN: stop, keep the best point
      return std::numeric_limits<double>::max();
    }
    return f;
  }

  void prepare(Index n);

  Summary run(Vector<N>& x, double stop_value, ObjectiveThunk thunk, void* context);

  NloptOptions nlopt_;
  nlopt_algorithm algorithm_;
  std::optional<nlopt::opt> opt_;
  Index prepared_n_ = -1;
  std::vector<double> xv_;
  Vector<N> x_ = zero_vector<N>(), grad_ = zero_vector<N>(), last_reported_ = zero_vector<N>();
  ObjectiveThunk thunk_ = nullptr;
  void* context_ = nullptr;
  int evaluations_ = 0, jacobians_ = 0;
  bool non_finite_ = false, stopped_by_user_ = false;
  std::exception_ptr thrown_;  // what a user's F or Jacobian threw during optimize()
};

template <int N>
Summary NloptEngine<N>::solve(const FixedPointProblem<N>& problem, Vector<N>& x) {
  detail::check_initial_guess(name(), problem, x);
  return run_residual<N>(detail::ResidualSource<N, N>(problem), x);
}

template <int N>
Summary NloptEngine<N>::solve_least_squares(const RootProblem<N, Dynamic>& problem, Vector<N>& x) {
  return solve<Dynamic>(problem, x);
}

template <int N>
Summary NloptEngine<N>::minimize(const ObjectiveProblem<N>& problem, Vector<N>& x) {
  detail::check_initial_guess(name(), problem.size(), x);
  struct Context {
    NloptEngine* engine;
    const ObjectiveProblem<N>* problem;
  } ctx{this, &problem};
  const double stop = nlopt_.stop_value.value_or(-std::numeric_limits<double>::infinity());
  Summary s = run(
      x, stop,
      +[](void* data, const Vector<N>& at, Vector<N>* grad) {
        auto* c = static_cast<Context*>(data);
        const double f = c->problem->evaluate(at);
        ++c->engine->evaluations_;
        c->engine->report_evaluation(at, std::numeric_limits<double>::quiet_NaN());
        if (grad != nullptr) {
          if (c->problem->has_gradient()) {
            c->problem->gradient(at, *grad);
          } else {
            c->engine->evaluations_ += c->engine->scalar_gradient(*c->problem, at, f, *grad);
          }
          ++c->engine->jacobians_;
        }
        return f;
      },
      &ctx);
  s.residual_norm = std::numeric_limits<double>::quiet_NaN();  // not a residual problem
  s.record_answer(x, this->options_.stop, /*minimised=*/true);
  return s;
}

template <int N>
Summary NloptEngine<N>::run(Vector<N>& x, double stop_value, ObjectiveThunk thunk, void* context) {
  detail::require_inside_box<N>("nlopt", nlopt_.lower_bounds, nlopt_.upper_bounds, x);
  const Index n = x.size();
  if (!opt_ || prepared_n_ != n) prepare(n);
  if constexpr (N == Dynamic) x_.resize(n), grad_.resize(n), last_reported_.resize(n);
  opt_->set_stopval(stop_value);
  thunk_ = thunk;
  context_ = context;
  evaluations_ = jacobians_ = 0;
  non_finite_ = stopped_by_user_ = false;
  thrown_ = nullptr;
  for (Index i = 0; i < n; ++i) xv_[static_cast<size_t>(i)] = x[i];

  Summary s;
  s.engine = name();
  double f = std::numeric_limits<double>::quiet_NaN();
  nlopt::result result = nlopt::FAILURE;
  try {
    result = opt_->optimize(xv_, f);
  } catch (const nlopt::roundoff_limited&) {
    result = nlopt::ROUNDOFF_LIMITED;
  } catch (const nlopt::forced_stop&) {
    result = nlopt::FORCED_STOP;
  } catch (const std::exception& e) {
    result = opt_->last_optimize_result();
    s.message = e.what();
  }
  if (thrown_) {  // the user's exception, unchanged, now that no NLopt frame is left to unwind
    std::exception_ptr thrown = std::move(thrown_);
    thrown_ = nullptr;
    std::rethrow_exception(thrown);
  }
  switch (result) {
    case nlopt::SUCCESS:
    case nlopt::STOPVAL_REACHED:
    case nlopt::FTOL_REACHED:
    case nlopt::XTOL_REACHED:
      s.status = Status::kConverged;
      break;
    case nlopt::MAXEVAL_REACHED:
      s.status = Status::kMaxEvaluations;
      break;
    case nlopt::MAXTIME_REACHED:
      s.status = Status::kMaxIterations;
      s.message = "NLopt time limit reached";
      break;
    case nlopt::ROUNDOFF_LIMITED:
      s.status = Status::kStagnated;
      s.message = "NLopt: roundoff limited";
      break;
    case nlopt::FORCED_STOP:
      s.status = stopped_by_user_ ? Status::kStoppedByCallback
                 : non_finite_    ? Status::kNonFinite
                                  : Status::kSolverFailure;
      break;
    default:
      s.status = Status::kSolverFailure;
      if (s.message.empty()) s.message = "NLopt failed (result " + std::to_string(result) + ")";
      break;
  }
  const Vector<N> best = Eigen::Map<const Vector<N>>(xv_.data(), n);
  if (best.allFinite()) {
    s.step_norm = (best - x).template lpNorm<Eigen::Infinity>();  // from x0: NLopt hides steps
    x = best;
  }
  s.iterations = opt_->get_numevals();  // NLopt counts objective evaluations, not iterations
  s.function_evaluations = evaluations_;
  s.jacobian_evaluations = jacobians_;
  if (std::isfinite(f)) s.objective = f;
  return s;
}

template <int N>
void NloptEngine<N>::prepare(Index n) {
  opt_.emplace(static_cast<nlopt::algorithm>(algorithm_), static_cast<unsigned>(n));
  auto bounds = [n](const Eigen::VectorXd& b, double fill) {
    std::vector<double> v(static_cast<size_t>(n), fill);
    for (Index i = 0; i < b.size(); ++i) v[static_cast<size_t>(i)] = b[i];
    return v;
  };
  const double inf = std::numeric_limits<double>::infinity();
  opt_->set_lower_bounds(bounds(nlopt_.lower_bounds, -inf));
  opt_->set_upper_bounds(bounds(nlopt_.upper_bounds, inf));
  const StopCriteria& stop = this->options_.stop;
  if (stop.step_tolerance) opt_->set_xtol_abs(*stop.step_tolerance);
  if (nlopt_.relative_step_tolerance > 0.0) opt_->set_xtol_rel(nlopt_.relative_step_tolerance);
  opt_->set_maxeval(stop.max_evaluations);
  if (nlopt_.initial_step) opt_->set_initial_step(*nlopt_.initial_step);
  opt_->set_min_objective(&NloptEngine::trampoline, this);
  xv_.assign(static_cast<size_t>(n), 0.0);
  prepared_n_ = n;
}

// Compiled once in the library for its sizes (nlobs/solvers/library_sizes.hpp).
#define NLOBS_EXTERN_NLOPT_ENGINE(n) extern template class NloptEngine<n>;
NLOBS_FOR_EACH_LIBRARY_SIZE(NLOBS_EXTERN_NLOPT_ENGINE)
#undef NLOBS_EXTERN_NLOPT_ENGINE

}  // namespace nlobs
