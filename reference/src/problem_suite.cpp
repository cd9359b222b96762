#include "nlobs/reference/problem_suite.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <new>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "nlobs/common/printable.hpp"
#include "nlobs/reference/petsc_solver.hpp"
#include "nlobs/reference/reference_engines.hpp"
#include "nlobs/reference/timing.hpp"
#include "nlobs/solvers/engine_registry.hpp"
#include "nlobs/solvers/root_adapter.hpp"
#include "petsc_option_rules.hpp"

namespace nlobs::reference {
namespace {

// A closed box inside the problem's: each strict bound √ε · max(1, |bound|) inward. For the
// engines whose boxes are closed (Ceres, NLopt): they never evaluate F on a strict bound either.
// One ulp inward is not enough: where F is ln c, its derivative 1/c at c = 5e-324 is infinite,
// and a method that jumps to the bound (NLopt's SLSQP does) stops on a non-finite Jacobian.
BoxBounds closed_inside(const TestProblem& p) {
  BoxBounds box{p.lower, p.upper};
  const double margin = std::sqrt(std::numeric_limits<double>::epsilon());
  auto inward = [margin](double bound, double towards) {
    return bound + std::copysign(margin * std::max(1.0, std::abs(bound)), towards);
  };
  // Never past the other side (or its own inward point): the box stays valid, if thin.
  const Index n = std::max(p.lower.size(), p.upper.size());
  auto other = [&](const Eigen::VectorXd& side, Index i, double none) {
    return side.size() == n ? side[i] : none;
  };
  const double inf = std::numeric_limits<double>::infinity();
  for (Index i = 0; i < p.strict_lower.size(); ++i) {
    if (p.strict_lower[i] && std::isfinite(box.lower[i])) {
      box.lower[i] = std::min(inward(box.lower[i], 1.0), other(p.upper, i, inf));
    }
  }
  for (Index i = 0; i < p.strict_upper.size(); ++i) {
    if (p.strict_upper[i] && std::isfinite(box.upper[i])) {
      box.upper[i] = std::max(inward(box.upper[i], -1.0), other(box.lower, i, -inf));
    }
  }
  return box;
}

struct Outcome {
  std::string status;
  long f_evals = 0, j_evals = 0;
  std::string message;
};

// Each (pair, solver) is timed over ~1 ms of repeated solves, at most 201 of them: the whole
// suite stays a few seconds.
constexpr double kTimingNs = 1e6;
constexpr long kMaxTimedCalls = 201;

// A fall of ‖F‖ counts when it goes below (1 − this) × the value at the fall before it, as the
// engines' progress window has it (ProgressWindow): rounding-level jitter near a root is none.
constexpr double kMeaningfulFall = kMeaningfulResidualFall;

// Counts the evaluations of F (or G) one solve makes and refuses those beyond its budget or past
// its deadline: the refused call returns NaN without calling the problem, and the row becomes
// max_evaluations or time_limit.
struct Meter {
  using Clock = std::chrono::steady_clock;
  long count = 0;
  long cap = std::numeric_limits<long>::max();
  bool refused = false;    // an evaluation beyond the budget was asked for
  bool timed_out = false;  // an evaluation past the deadline was asked for
  int late_calls = 0;      // evaluations asked for past the deadline
  bool timed = false;
  Clock::time_point deadline{};
  double time_limit_s = 0.0;
  // Progress, as the engines' StopCriteria::progress_window counts it: the count at the last
  // evaluation that brought ‖D_f F‖₂ below (1 − kMeaningfulFall) × its value at the fall before
  // (the anchor). A slow but steady descent makes progress; jitter at a floor does not.
  const Eigen::VectorXd* f_scale = nullptr;
  double anchor = std::numeric_limits<double>::infinity();
  long last_fall = 0;
  Eigen::VectorXd scratch, residual;
  void reset(long budget, double limit_s) {
    count = 0;
    cap = budget;
    refused = timed_out = false;
    late_calls = 0;
    anchor = std::numeric_limits<double>::infinity();
    last_fall = 0;
    timed = std::isfinite(limit_s);
    time_limit_s = limit_s;
    if (timed) {
      deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                    std::chrono::duration<double>(limit_s));
    }
  }
  // True when the deadline has passed (and notes it).
  bool late() {
    if (!timed || Clock::now() < deadline) return false;
    timed_out = true;
    ++late_calls;
    return true;
  }
  // After the evaluation just taken: f = F(x) (NaN or inf: no progress).
  void saw(const Eigen::VectorXd& f) {
    if (!f.allFinite()) return;
    double norm = f.stableNorm();
    if (f_scale && f_scale->size() == f.size()) {
      scratch = f.cwiseProduct(*f_scale);
      norm = scratch.stableNorm();
    }
    if (norm < (1.0 - kMeaningfulFall) * anchor) {
      anchor = norm;
      last_fall = count;
    }
  }
  // After an evaluation of G: F = G(x) − x.
  void saw_fixed_point(const Eigen::VectorXd& x, const Eigen::VectorXd& g) {
    if (g.size() != x.size()) return;  // the engine names a G of the wrong size
    residual = g - x;
    saw(residual);
  }
  // Evaluations made since ‖D_f F‖ last fell meaningfully (all of them if it never did).
  long past_progress() const { return count - last_fall; }
  // True when one more evaluation is within the budget and the time limit (and counts it).
  bool take() {
    if (count >= cap) {
      refused = true;
      return false;
    }
    if (late()) return false;
    ++count;
    return true;
  }
};

// Thrown from G into the engines when one keeps asking for evaluations past the time limit: it
// would otherwise hold the suite. (A reference engine keeps it while its C library stops, and
// throws it then: nothing unwinds through C.)
struct TimeLimitStop {};
constexpr int kLateCallsBeforeStop = 10;

// Ends the timing of a solve its engine refused (Status::kInvalidInput): one attempt, no answer.
struct RefusedSolve {};

// G with the problem's own F (TestProblem::residual, its Jacobian and sparse pattern) attached
// as its residual form, for a problem posed as x = G(x); G itself otherwise (to_fixed_point
// attached F already).
FixedPointProblem<Dynamic> with_own_residual(const TestProblem& p,
                                             const FixedPointProblem<Dynamic>& g) {
  if (!p.fixed_point || (g.has_jacobian() && !p.residual.has_jacobian())) return g;
  const RootProblem<Dynamic>* f = &p.residual;
  FixedPointProblem<Dynamic> out = g.with_residual(
      [f](const Eigen::VectorXd& x, Eigen::VectorXd& value) { f->evaluate(x, value); },
      g.has_jacobian()
          ? FixedPointProblem<Dynamic>::JacobianMap(
                [f](const Eigen::VectorXd& x, Eigen::MatrixXd& jac) { f->jacobian(x, jac); })
          : FixedPointProblem<Dynamic>::JacobianMap());
  if (p.residual.sparse_jacobian_state()) {
    out = out.with_sparse_jacobian_state(p.residual.sparse_jacobian_state());
  }
  return out;
}

// F as the suite judges an answer by it: an exception F throws is a value that is not finite
// (never solved).
void judged_residual(const RootProblem<Dynamic>& f, const Eigen::VectorXd& x,
                     Eigen::VectorXd& out) {
  try {
    f.evaluate(x, out);
  } catch (...) {
    out.setConstant(f.residual_size(), std::numeric_limits<double>::quiet_NaN());
  }
}

// G for the engines (a user's and the reference engines among them): metered, its Jacobian kept,
// its exceptions left to the engine (an engine that throws is a row, engine_threw; a reference
// engine keeps the exception while its C library stops, then throws it). The result refers to
// `g`, which must outlive it.
FixedPointProblem<Dynamic> metered(const FixedPointProblem<Dynamic>& g, Meter& meter) {
  const FixedPointProblem<Dynamic>* p = &g;
  auto map = [p, &meter](const Eigen::VectorXd& x, Eigen::VectorXd& out) {
    if (!meter.take()) {
      if (meter.late_calls > kLateCallsBeforeStop) throw TimeLimitStop{};
      out.setConstant(p->size(), std::numeric_limits<double>::quiet_NaN());
      return;
    }
    p->evaluate(x, out);
    meter.saw_fixed_point(x, out);
  };
  // F itself, when G carries it (FixedPointProblem::residual): metered alike, one evaluation.
  auto residual = [p, &meter](const Eigen::VectorXd& x, Eigen::VectorXd& out) {
    if (!meter.take()) {
      if (meter.late_calls > kLateCallsBeforeStop) throw TimeLimitStop{};
      out.setConstant(p->size(), std::numeric_limits<double>::quiet_NaN());
      return;
    }
    p->residual(x, out);
    meter.saw(out);
  };
  // A Jacobian past the deadline is refused too (NaN).
  const auto late = [&meter, p](Eigen::MatrixXd& jac) {
    if (!meter.late()) return false;
    if (meter.late_calls > kLateCallsBeforeStop) throw TimeLimitStop{};
    jac.setConstant(p->size(), p->size(), std::numeric_limits<double>::quiet_NaN());
    return true;
  };
  // The sparse Jacobian (declared, or detected at the engine's start) goes with the residual
  // form: an engine with a sparse path takes it, as it would from the problem itself.
  const auto with_sparse = [&g](FixedPointProblem<Dynamic> out) {
    return g.sparse_jacobian_state() ? out.with_sparse_jacobian_state(g.sparse_jacobian_state())
                                     : out;
  };
  if (!g.has_jacobian()) {
    auto out = FixedPointProblem<Dynamic>::from_map(map, g.size());
    return g.has_residual() ? with_sparse(out.with_residual(residual)) : out;
  }
  auto jacobian = [p, late](const Eigen::VectorXd& x, Eigen::MatrixXd& jac) {
    if (!late(jac)) p->jacobian(x, jac);
  };
  auto out =
      FixedPointProblem<Dynamic>::with_jacobian(map, jacobian, g.size(), g.jacobian_source());
  if (!g.has_residual()) return out;
  return with_sparse(
      out.with_residual(residual, [p, late](const Eigen::VectorXd& x, Eigen::MatrixXd& jac) {
        if (!late(jac)) p->residual_jacobian(x, jac);
      }));
}

// MPI's start and PETSc's first use of each of its types (their registration, ~10 ms) happen
// here, untimed: one solve of a 2-unknown system with the name's type and options (its printing
// viewers left out). A failure here is the row's to report.
void warm_up_petsc(const std::string& name) {
  initialize_petsc();
  try {
    PetscSnesOptions o = PetscSnesSolver::parse_name(name);
    std::erase_if(o.options, [](const auto& kv) { return petsc_rules::names_a_viewer(kv.first); });
    PetscSnesSolver snes(2, std::move(o), [](const Eigen::VectorXd& v, Eigen::VectorXd& f) {
      f = v.array() * v.array() - 1.0;
    });
    Eigen::VectorXd x = Eigen::VectorXd::Constant(2, 2.0);
    (void)snes.solve(x);
  } catch (...) {
  }
}

double distance_to_solutions(const TestProblem& p, const Eigen::VectorXd& x) {
  if (p.solutions.empty()) return std::numeric_limits<double>::quiet_NaN();
  if (!x.allFinite()) return std::numeric_limits<double>::infinity();
  double best = std::numeric_limits<double>::infinity();
  for (const Eigen::VectorXd& s : p.solutions) {
    best = std::min(best, (x - s).lpNorm<Eigen::Infinity>());
  }
  return best;
}

bool selected(const ProblemStart& s, const SuiteOptions& options) {
  return options.starts.empty() ||
         std::find(options.starts.begin(), options.starts.end(), s.label) != options.starts.end();
}

}  // namespace

int count_suite_pairs(const std::vector<TestProblem>& problems, const SuiteOptions& options) {
  int total = 0;
  for (const TestProblem& p : problems) {
    for (const ProblemStart& s : p.starts) total += selected(s, options);
  }
  return total;
}

std::vector<std::string> default_suite_solvers() {
  std::vector<std::string> s = {"picard",
                                "aitken",
                                "steffensen",
                                "anderson",
                                "newton",
                                "newton:linesearch=1",
                                "newton:trustregion=1",
                                "dogleg",
                                "levenberg-marquardt",
                                "levenberg-marquardt:geodesic=1",
                                "pseudo-transient",
                                "auto",
                                "ceres",
                                "ceres:dogleg",
                                "nlopt:LD_SLSQP",
                                "nlopt:LN_BOBYQA"};
  for (const auto& r : reference_suite_solvers()) s.push_back(r);
  return s;
}

std::vector<std::string> reference_suite_solvers() {
  return {"minpack:hybrj", "kinsol:newton", "gsl:hybridsj", "gsl:gnewton"};
}

std::vector<std::string> all_reference_solvers() {
  std::vector<std::string> s = reference_suite_solvers();
  for (const char* more : {"kinsol:fp", "kinsol:fp-aa2", "kinsol:newton-band", "kinsol:newton-klu",
                           "kinsol:newton-spgmr"}) {
    s.emplace_back(more);
  }
  if (petsc_available()) {
    for (const std::string& name : PetscSnesSolver::names()) s.push_back(name);
  }
  return s;
}

double suite_threshold(const ProblemSetEntry& set, const SuiteOptions& options) {
  const double t =
      std::isnan(options.solved_threshold) ? set.solved_threshold : options.solved_threshold;
  if (!(t > 0.0) || !std::isfinite(t)) {
    throw InvalidInput("the solved threshold on |F|2 must be finite and > 0 (got " +
                       std::to_string(t) + ")");
  }
  return t;
}

std::vector<std::string> split_spec_list(const std::string& list) {
  std::vector<std::string> out;
  size_t start = 0;
  while (start <= list.size()) {
    const size_t comma = list.find(',', start);
    const std::string item =
        list.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (!item.empty()) {
      const bool continues = item.find('=') != std::string::npos &&
                             item.find(':') == std::string::npos && !out.empty() &&
                             out.back().find(':') != std::string::npos;
      if (continues) {
        out.back() += "," + item;
      } else {
        out.push_back(item);
      }
    }
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

std::vector<SuiteRow> run_suite(const ProblemSetEntry& set,
                                const std::vector<TestProblem>& problems,
                                const std::vector<std::string>& solvers,
                                const SuiteOptions& options) {
  const double threshold = suite_threshold(set, options);
  if (options.evaluations_per_dimension < 1) {
    throw InvalidInput("the evaluation budget per dimension must be >= 1");
  }
  if (solvers.empty()) throw InvalidInput("no solver listed");
  if (!(options.time_limit_s > 0.0)) {
    throw InvalidInput("the time limit per solve must be > 0 seconds (+inf: none), got " +
                       std::to_string(options.time_limit_s));
  }
  register_reference_engines();
  auto& registry = EngineRegistry<Dynamic>::global();
  SolverOptions base;
  base.stop.step_tolerance = 1e-12;
  base.stop.residual_tolerance = 1e-10;
  // Validate every name and start label before running anything.
  for (const std::string& s : solvers) {
    try {
      (void)registry.create(s, base);
    } catch (const InvalidInput& e) {
      std::string refs;
      for (const auto& r : all_reference_solvers()) refs += ", " + r;
      throw std::invalid_argument(std::string(e.what()) + "; references" + refs);
    }
    // PETSc's own refusals (a build without it included) in its rows.
    if (PetscSnesSolver::is_name(s) && petsc_available()) warm_up_petsc(s);
  }
  std::set<std::string> labels;
  for (const TestProblem& p : problems) {
    for (const ProblemStart& s : p.starts) labels.insert(s.label);
  }
  for (const std::string& wanted : options.starts) {
    if (!labels.count(wanted)) {
      std::string valid;
      for (const auto& l : labels) valid += (valid.empty() ? "" : ", ") + l;
      throw std::invalid_argument("no problem of set '" + set.name + "' has a start '" +
                                  wanted.substr(0, 60) + "'; its starts: " + valid);
    }
  }
  const int total = count_suite_pairs(problems, options);

  int done = 0;
  std::vector<SuiteRow> rows;
  Meter meter;
  for (const TestProblem& p : problems) {
    const Index n = p.size();
    // K (n + 1), saturated (K ≤ 1e6 and n ≤ kMaxProblemDimension keep it far from overflow).
    const long budget = n + 1 > std::numeric_limits<long>::max() / options.evaluations_per_dimension
                            ? std::numeric_limits<long>::max()
                            : options.evaluations_per_dimension * static_cast<long>(n + 1);
    const FixedPointProblem<Dynamic> g =
        p.fixed_point ? *p.fixed_point : to_fixed_point<Dynamic>(p.residual);
    const FixedPointProblem<Dynamic> engine_g = metered(g, meter);
    // The reference engines solve the problem's F itself (TestProblem::residual, with its
    // Jacobian and sparse pattern) as their drivers do; KINSOL's fixed-point strategies iterate
    // G. A problem posed as x = G(x) gets its F attached for them.
    // (metered() refers to the problem it is given: kept here for the loop's life.)
    const FixedPointProblem<Dynamic> g_with_f = with_own_residual(p, g);
    const FixedPointProblem<Dynamic> reference_g = metered(g_with_f, meter);
    meter.f_scale = &p.f_scale;
    // The pattern of a with_autodiff F is detected once per problem (at the first start), here
    // and untimed: the first solver of the list would otherwise be timed with it. What it
    // throws, an engine meets again (and its row says so).
    try {
      (void)p.residual.sparse_jacobian(p.starts.front().x);
    } catch (...) {
    }
    for (const ProblemStart& start : p.starts) {
      if (!selected(start, options)) continue;
      for (const std::string& s : solvers) {
        SuiteRow row;
        row.set = set.name;
        row.problem = p.name;
        row.n = static_cast<int>(n);
        row.start = start.label;
        row.start_scale = start.scale;
        row.solver = s;
        Eigen::VectorXd x = start.x;
        Outcome outcome;
        meter.reset(budget, options.time_limit_s);
        // Whatever a solver's options, set-up or run throw, the row says so and the suite goes
        // on: invalid_input (options or set-up refused, the problem's box refused),
        // out_of_memory (std::bad_alloc), engine_threw (anything else, `throw 42` included).
        bool setting_up = true;
        // A solve ended by an exception (the time limit's, an engine's) has no mean over repeated
        // calls: its row gives the wall time of that one attempt, not 0. So does a row the time
        // limit ended: the row is the last of the timed calls, and a mean with earlier calls that
        // ended in time could show less than the limit it was stopped at.
        auto attempt_started = std::chrono::steady_clock::now();
        auto attempt_ns = [&attempt_started] {
          return std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() -
                                                          attempt_started)
              .count();
        };
        try {
          {
            SolverOptions o = base;
            o.stop.max_evaluations = static_cast<int>(std::min<long>(budget, 1L << 30));
            const std::string problem_start = p.name + "/" + start.label;
            if (options.monitor) {
              o.iteration_callback = [&options, &s, &problem_start](const IterationRecord& r) {
                options.monitor(s, problem_start, r);
                return IterationDecision::kContinue;
              };
            }
            auto engine = registry.create(s, o);
            const bool reference = is_reference_engine(s);
            // The problem's box reaches the engines that take bounds (its strict sides those
            // that take them; Ceres and NLopt the closed box inside it); the others run
            // unbounded and are judged alike (outside_bounds). levenberg-marquardt:geodesic=1
            // and a user's engine may refuse it: invalid_input.
            if ((p.lower.size() > 0 || p.upper.size() > 0) && engine->accepts_bounds()) {
              engine->set_bounds(engine->accepts_strict_bounds() ? p.bounds() : closed_inside(p));
            }
            // The problem's scaling likewise (the Newton-type engines; docs/solvers.md).
            if ((p.u_scale.size() > 0 || p.f_scale.size() > 0) && engine->accepts_scaling()) {
              engine->set_scaling({p.u_scale, p.f_scale});
            }
            setting_up = false;
            row.ns = mean_ns_per_call(
                [&] {
                  attempt_started = std::chrono::steady_clock::now();
                  x = start.x;
                  meter.reset(budget, options.time_limit_s);
                  const Summary sum =
                      solve_or_report(*engine, reference ? reference_g : engine_g, x);
                  // The metered count: every evaluation of G the engine made. A reference
                  // engine's row shows its library's own account (Summary::library_status).
                  outcome = {sum.library_status.empty() ? std::string(to_string(sum.status))
                                                        : sum.library_status,
                             meter.count, sum.jacobian_evaluations, sum.message};
                  // Refused (the problem's size, its Jacobian, the library's set-up): a row
                  // without an answer, timed once.
                  if (sum.status == Status::kInvalidInput) throw RefusedSolve{};
                },
                kTimingNs, 1, options.monitor ? 1 : kMaxTimedCalls);
          }
          if (meter.timed_out) row.ns = attempt_ns();
        } catch (const RefusedSolve&) {
          row.ns = attempt_ns();
          x.resize(0);  // the refusal's outcome is set: no answer
        } catch (const TimeLimitStop&) {
          row.ns = attempt_ns();
          outcome = {"time_limit", meter.count, 0, ""};
          x.resize(0);  // unwound: no answer
        } catch (const std::bad_alloc&) {
          row.ns = attempt_ns();
          outcome = {"out_of_memory", meter.count, 0, "std::bad_alloc: not enough memory"};
          x.resize(0);
        } catch (...) {
          row.ns = attempt_ns();
          const bool refused_input = setting_up && [] {
            try {
              throw;
            } catch (const std::invalid_argument&) {  // InvalidInput is one
              return true;
            } catch (...) {
              return false;
            }
          }();
          outcome = {refused_input ? "invalid_input" : "engine_threw", meter.count, 0,
                     current_exception_text()};
          x.resize(0);  // no answer
        }
        row.message = printable(outcome.message);
        row.residual = row.scaled_residual = std::numeric_limits<double>::infinity();
        if (x.size() == n && x.allFinite()) {
          Eigen::VectorXd f(n);
          judged_residual(p.residual, x, f);
          if (f.allFinite()) {
            row.residual = f.norm();
            row.scaled_residual = p.f_scale.size() ? p.scaled_norm(f) : row.residual;
          }
        }
        if (x.size() == n) row.x = x;
        row.status = outcome.status;
        const bool in_box = x.size() == n && !p.first_outside_bounds(x);
        // A point that is not finite keeps the solver's own account (non_finite, ...): it is no
        // point outside the box.
        if (x.size() == n && x.allFinite() && !in_box) row.status = "outside_bounds";
        // An evaluation asked for beyond the budget was refused: whatever the point, not solved.
        if (meter.timed_out) {
          row.status = "time_limit";
          std::ostringstream why;
          why << "asked for an evaluation after the time limit of " << options.time_limit_s
              << " s (refused"
              << (meter.late_calls > kLateCallsBeforeStop
                      ? "; asked ten more times, stopped by an exception)"
                      : ")");
          // What the engine said of the NaN it was given is beside the point.
          row.message = why.str();
        } else if (meter.refused) {
          row.status = "max_evaluations";
          if (row.message.empty()) {
            row.message = "asked for an evaluation beyond the budget of " + std::to_string(budget) +
                          " (refused)";
          }
        }
        row.solved = x.size() == n && in_box && !meter.refused && !meter.timed_out &&
                     row.scaled_residual <= threshold;
        row.error =
            x.size() == n ? distance_to_solutions(p, x) : std::numeric_limits<double>::infinity();
        row.f_evals = outcome.f_evals;
        row.evals_past_progress = meter.past_progress();
        row.j_evals = outcome.j_evals;
        rows.push_back(std::move(row));
      }
      if (options.progress) options.progress(++done, total);
    }
  }
  return rows;
}

}  // namespace nlobs::reference
