#pragma once
// The built-in engines' registry entries. The library compiles add_builtin_engines<N> for its
// sizes (library_sizes.hpp) and EngineRegistry<N>::global() calls it there; include this
// header only to give the built-in engines fixed-size entries at another size N:
//   nlobs::add_builtin_engines<6>(nlobs::EngineRegistry<6>::global());
// (it compiles every engine at that size in the including file).
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "nlobs/solvers/broyden_engine.hpp"
#include "nlobs/solvers/ceres_engine.hpp"
#include "nlobs/solvers/dogleg_engine.hpp"
#include "nlobs/solvers/engine_registry.hpp"
#include "nlobs/solvers/fixed_point_engines.hpp"
#include "nlobs/solvers/levenberg_marquardt_engine.hpp"
#include "nlobs/solvers/newton_engine.hpp"
#include "nlobs/solvers/nlopt_engine.hpp"
#include "nlobs/solvers/polyalgorithm_engine.hpp"
#include "nlobs/solvers/pseudo_transient_engine.hpp"

namespace nlobs {

// The stages of `auto`, in order, each from x0: Newton first (the cheapest when it works), the
// dogleg where its full steps fail, Levenberg-Marquardt where the dogleg stagnates, the
// pseudo-transient flow last. Measured on the MGH set against other orders (docs/solvers.md).
inline constexpr const char* kAutoOrder = "newton/dogleg/levenberg-marquardt/pseudo-transient";

namespace detail {
// finite_difference=forward|central (alias fd), when given.
inline std::optional<FiniteDifference> read_finite_difference(EngineSpecReader& s) {
  const auto v = s.choice("finite_difference", {"forward", "central"});
  if (!v) return std::nullopt;
  return *v == "forward" ? FiniteDifference::kForward : FiniteDifference::kCentral;
}

// The keys linear_solver=…, preconditioner=… and ordering=… of the engines with a sparse path, and
// their reading: the linear-solver spec, or nullopt when none is given.
inline constexpr const char* kLinearKeyHelp =
    "auto|dense|band-lu|sparse-lu|klu|umfpack|gmres|bicgstab: the linear solver of a problem with "
    "a sparse Jacobian; default auto (band-lu, klu, or umfpack from 20000 unknowns)";
inline constexpr const char* kPreconditionerKeyHelp =
    "none|jacobi|ilu0|ilut|boomeramg, with linear_solver=gmres|bicgstab; default none";
inline constexpr const char* kOrderingKeyHelp =
    "amd|metis (nested dissection), with linear_solver=umfpack; default amd";
// The keys several engines share, with their old names as aliases (functions, not globals: the
// registry may be filled during another translation unit's static initialisation).
inline EngineOptionInfo finite_difference_key() {
  return {
      "finite_difference", "forward|central differences when no Jacobian; default central", {"fd"}};
}
inline EngineOptionInfo linear_solver_key() {
  return {"linear_solver", kLinearKeyHelp, {"linear"}};
}
inline std::optional<std::string> parse_linear_solver(const char* engine, EngineSpecReader& s,
                                                      std::string linear) {
  const std::optional<std::string> given = s.text("linear_solver");
  if (given) linear = *given;
  const std::optional<std::string> preconditioner = s.text("preconditioner");
  if (preconditioner) {
    if (linear != "gmres" && linear != "bicgstab") {
      throw InvalidInput(std::string(engine) + ": preconditioner=" + *preconditioner +
                         " needs linear_solver=gmres or bicgstab");
    }
    linear += ":preconditioner=" + *preconditioner;
  }
  const std::optional<std::string> ordering = s.text("ordering");
  if (ordering) {
    if (linear != "umfpack") {
      throw InvalidInput(std::string(engine) + ": ordering=" + *ordering +
                         " needs linear_solver=umfpack");
    }
    linear += ":ordering=" + *ordering;
  }
  if (!given && !preconditioner && !ordering) return std::nullopt;
  return linear;
}
}  // namespace detail

template <int N>
void add_builtin_engines(EngineRegistry<N>& registry) {
  // Idempotent: a name the registry already has an entry of (a second call, or the user's own
  // entry under a built-in's name) is left as it is.
  const auto add = [&registry](typename EngineRegistry<N>::Entry entry) {
    if (!registry.has_entry(entry.name)) registry.add(std::move(entry));
  };
  add({"picard", "x <- G(x)", {}, {"picard"}, [](EngineSpecReader&, SolverOptions o) {
         return std::make_unique<PicardEngine<N>>(std::move(o));
       }});
  add({"aitken",
       "component-wise Aitken delta^2 of the Picard sequence",
       {},
       {"aitken"},
       [](EngineSpecReader&, SolverOptions o) {
         return std::make_unique<AitkenEngine<N>>(std::move(o));
       }});
  add({"steffensen",
       "Aitken restarted every three iterates",
       {},
       {"steffensen"},
       [](EngineSpecReader&, SolverOptions o) {
         return std::make_unique<SteffensenEngine<N>>(std::move(o));
       }});
  add({"anderson",
       "Anderson acceleration (type II)",
       {{"depth", "m >= 0, the differences kept; default 3", {"m"}},
        {"damping", "beta in (0, 1]; default 1"},
        {"condition_limit",
         "drop old columns above this condition estimate; default 1e8",
         {"cond"}}},
       {"anderson", "anderson:depth=3,damping=0.5"},
       [](EngineSpecReader& s, SolverOptions o) {
         AndersonOptions a;
         if (auto v = s.integer("depth", 0, AndersonMixing<N>::kMaxDepth)) a.depth = *v;
         if (auto v = s.number("damping")) a.damping = *v;
         if (auto v = s.number("condition_limit")) a.condition_limit = *v;
         return std::make_unique<AndersonEngine<N>>(a, std::move(o));
       }});
  add({"newton",
       "Newton on F = G - x, any Jacobian source",
       {{"line_search", "0/1 Armijo backtracking; default 0", {"linesearch"}},
        {"trust_region",
         "0/1 dogleg trust region, a Jacobian every iterate; default 0",
         {"trustregion"}},
        detail::finite_difference_key(),
        detail::linear_solver_key(),
        {"preconditioner", detail::kPreconditionerKeyHelp},
        {"ordering", detail::kOrderingKeyHelp},
        {"jacobian_reuse",
         "1..1000 iterations one Jacobian (and its factorisation) serves: modified Newton "
         "(KINSOL: 10); default 1",
         {"reuse"}}},
       {"newton", "newton:line_search=1", "newton:trust_region=1",
        "newton:line_search=1,linear_solver=gmres,preconditioner=ilu0",
        "newton:line_search=1,jacobian_reuse=10"},
       [](EngineSpecReader& s, SolverOptions o) {
         NewtonOptions n;
         if (auto v = s.boolean("line_search")) n.line_search = *v;
         if (auto v = s.boolean("trust_region")) n.trust_region = *v;
         if (auto v = s.integer("jacobian_reuse", 1, 1000)) n.jacobian_reuse = *v;
         if (auto v = detail::read_finite_difference(s)) n.finite_difference = *v;
         if (auto v = detail::parse_linear_solver("newton", s, n.linear_solver)) {
           n.linear_solver = *v;
         }
         return std::make_unique<NewtonEngine<N>>(n, std::move(o));
       }});
  add({"dogleg",
       "Powell's hybrid method (MINPACK hybrj): trust region, dogleg steps, Broyden updates",
       {{"scaling",
         "none|jacobian: trust-region scaling D = I or Jacobian column norms "
         "(MINPACK mode 2|1); default none",
         {"scale"}},
        {"initial_radius_factor", "initial radius factor * |D x0|; default 100", {"factor"}},
        {"broyden_updates", "0/1 Broyden updates between Jacobians; default 1", {"broyden"}},
        detail::finite_difference_key()},
       {"dogleg", "dogleg:scaling=jacobian"},
       [](EngineSpecReader& s, SolverOptions o) {
         DoglegOptions d;
         if (auto v = s.choice("scaling", {"none", "jacobian"})) {
           d.scaling = *v == "none" ? DoglegOptions::Scaling::kNone
                                    : DoglegOptions::Scaling::kJacobianColumns;
         }
         if (auto v = s.number("initial_radius_factor")) d.initial_radius_factor = *v;
         if (auto v = s.boolean("broyden_updates")) d.broyden_updates = *v;
         if (auto v = detail::read_finite_difference(s)) d.finite_difference = *v;
         return std::make_unique<DoglegEngine<N>>(d, std::move(o));
       }});
  add({"broyden",
       "Broyden's good method: line search, Jacobian restarts, O(n^2) inverse updates (limited "
       "memory, O(k n), on a sparse Jacobian)",
       {{"max_backtracks",
         "step halvings before the Jacobian is renewed, 0..60; default 10",
         {"backtracks"}},
        {"max_updates",
         "updates before a fresh Jacobian regardless, 0 = off; default 0",
         {"updates"}},
        detail::finite_difference_key(),
        {"linear_solver",
         "auto|dense|band-lu|sparse-lu|klu|umfpack: H0 = J^-1 of a problem with a sparse "
         "Jacobian by this direct solver, the updates kept as vectors (limited memory), or "
         "dense H; default auto",
         {"linear"}},
        {"ordering", detail::kOrderingKeyHelp},
        {"memory",
         "updates the limited-memory form keeps before a fresh Jacobian, 1..1000; "
         "default 20"}},
       {"broyden", "broyden:finite_difference=forward,max_updates=20", "broyden:memory=50"},
       [](EngineSpecReader& s, SolverOptions o) {
         BroydenOptions b;
         if (auto v = s.integer("max_backtracks", 0, 60)) b.max_backtracks = *v;
         if (auto v = s.integer("max_updates", 0, 1 << 30)) b.max_updates = *v;
         if (auto v = s.integer("memory", 1, 1000)) b.memory = *v;
         if (auto v = s.text("preconditioner")) {
           throw InvalidInput("broyden: preconditioner=" + *v +
                              " does not apply: H0 is applied by a direct solver "
                              "(linear=auto|band-lu|sparse-lu|klu|umfpack)");
         }
         if (auto v = detail::parse_linear_solver("broyden", s, b.linear_solver)) {
           b.linear_solver = *v;
         }
         if (auto v = detail::read_finite_difference(s)) b.finite_difference = *v;
         return std::make_unique<BroydenEngine<N>>(b, std::move(o));
       }});
  add({"levenberg-marquardt",
       "Levenberg-Marquardt as MINPACK lmder (More's lambda and scaling), square or least "
       "squares",
       {{"scaling",
         "none|jacobian: D = I or Jacobian column norms (More); default none",
         {"scale"}},
        {"initial_radius_factor", "initial radius factor * |D x0|; default 100", {"factor"}},
        {"geodesic_acceleration",
         "0/1 geodesic acceleration (Transtrum-Sethna); default 0",
         {"geodesic"}},
        // MINPACK's ftol: on this engine `ftol` is this, not the common residual_tolerance.
        {"function_tolerance",
         "relative reduction of |F|^2 (MINPACK's ftol); default 1e-10",
         {"ftol"}},
        {"gradient_tolerance",
         "cosine of F and the columns of J (MINPACK's gtol); default 1e-12",
         {"gtol"}},
        detail::finite_difference_key(),
        {"linear_solver",
         "auto|cholmod|dense: the step of a problem with a sparse Jacobian by CHOLMOD's sparse "
         "Cholesky of the normal equations, or dense QR; default auto (cholmod)",
         {"linear"}}},
       {"levenberg-marquardt", "levenberg-marquardt:geodesic_acceleration=1",
        "levenberg-marquardt:scaling=jacobian", "levenberg-marquardt:linear_solver=dense"},
       [](EngineSpecReader& s, SolverOptions o) {
         LevenbergMarquardtOptions l;
         if (auto v = s.choice("scaling", {"none", "jacobian"})) {
           l.scale_by_jacobian_columns = *v == "jacobian";
         }
         if (auto v = s.number("initial_radius_factor")) l.initial_radius_factor = *v;
         if (auto v = s.boolean("geodesic_acceleration")) l.geodesic_acceleration = *v;
         if (auto v = s.number("function_tolerance")) l.function_tolerance = *v;
         if (auto v = s.number("gradient_tolerance")) l.gradient_tolerance = *v;
         if (auto v = detail::read_finite_difference(s)) l.finite_difference = *v;
         if (auto v = s.text("linear_solver")) l.linear_solver = *v;
         return std::make_unique<LevenbergMarquardtEngine<N>>(l, std::move(o));
       }});
  add({"pseudo-transient",
       "pseudo-transient continuation (Kelley-Keyes): implicit Euler on a flow to the root, "
       "growing "
       "step",
       {{"flow", "residual|fixed-point: dx/dt = -F = x - G(x) or G(x) - x; default residual"},
        {"initial_pseudo_step",
         "initial pseudo time step, >= 2.22e-16 (machine epsilon); default 1e-2",
         {"delta0"}},
        {"max_pseudo_step", "largest pseudo time step; default 1e12", {"delta_max"}},
        {"pseudo_step_growth",
         "factor gamma >= 1 on the SER step update (PETSc: 1.1), <= 10; default 1",
         {"growth"}},
        detail::finite_difference_key(),
        detail::linear_solver_key(),
        {"preconditioner", detail::kPreconditionerKeyHelp},
        {"ordering", detail::kOrderingKeyHelp}},
       {"pseudo-transient:flow=fixed-point",
        "pseudo-transient:flow=fixed-point,initial_pseudo_step=1e-4",
        "pseudo-transient:flow=fixed-point,linear_solver=gmres,preconditioner=ilu0"},
       [](EngineSpecReader& s, SolverOptions o) {
         PseudoTransientOptions p;
         if (auto v = s.choice("flow", {"residual", "fixed-point"})) {
           p.flow = *v == "residual" ? PseudoTransientOptions::Flow::kResidual
                                     : PseudoTransientOptions::Flow::kFixedPoint;
         }
         if (auto v = s.number("initial_pseudo_step")) p.initial_pseudo_step = *v;
         if (auto v = s.number("max_pseudo_step")) p.max_pseudo_step = *v;
         if (auto v = s.number("pseudo_step_growth")) p.pseudo_step_growth = *v;
         // δ_min follows a δ₀ below its default (δ₀ itself is checked by the engine: >= ε).
         if (p.min_pseudo_step > p.initial_pseudo_step) {
           p.min_pseudo_step =
               std::max(p.initial_pseudo_step, PseudoTransientOptions::kMinPseudoStep);
         }
         if (auto v = detail::read_finite_difference(s)) p.finite_difference = *v;
         if (auto v = detail::parse_linear_solver("pseudo-transient", s, p.linear_solver)) {
           p.linear_solver = *v;
         }
         return std::make_unique<PseudoTransientEngine<N>>(p, std::move(o));
       }});
  add({"auto",
       "polyalgorithm: engines in order within one budget, until one answer is usable",
       {{"order", std::string("engine names separated by '/'; default ") + kAutoOrder},
        {"from", "start|best: each stage from x0 or from the best point so far; default start"},
        {"shared_minimum",
         "stop (local_minimum) when this many stages end at the same point without "
         "progress, 0 = off; default 2"},
        {"dense_stage_limit",
         "on a problem with a sparse Jacobian and more unknowns than this, skip the stages "
         "without a sparse path (dense n x n J), 0 = never; default 1000",
         {"dense_limit"}}},
       {"auto", "auto:order=dogleg/levenberg-marquardt,from=best"},
       [](EngineSpecReader& s, SolverOptions o) {
         PolyalgorithmOptions p;
         if (auto v = s.choice("from", {"start", "best"})) p.restart_from_best = *v == "best";
         if (auto v = s.integer("shared_minimum", 0, 1000)) p.shared_minimum = *v;
         if (auto v = s.integer("dense_stage_limit", 0, std::numeric_limits<int>::max())) {
           p.dense_stage_limit = *v;
         }
         const std::string order = s.text("order").value_or(kAutoOrder);
         std::vector<std::unique_ptr<Engine<N>>> stages;
         for (std::size_t at = 0; at <= order.size();) {
           const std::size_t slash = std::min(order.find('/', at), order.size());
           const std::string stage = order.substr(at, slash - at);
           if (stage.empty() || parse_engine_spec(stage).name == "auto") {
             throw InvalidInput("auto: order=" + quoted_excerpt(order) +
                                " needs engine names "
                                "other than auto, separated by '/'");
           }
           // Stages by name from the process-wide registry (a user's engines included).
           stages.push_back(EngineRegistry<N>::global().create(stage, o));
           at = slash + 1;
         }
         return std::make_unique<PolyalgorithmEngine<N>>(std::move(stages), p, std::move(o));
       }});
  add({"ceres",
       "Ceres least squares, Levenberg-Marquardt or dogleg",
       {{"<lm|dogleg>", "trust-region strategy; default lm"},
        {"backend", "auto|tiny|solver; default auto"},
        {"function_tolerance", "relative cost change; default 1e-10", {"function_tol"}},
        {"gradient_tolerance", "default 1e-12", {"gradient_tol"}},
        {"jacobi_scaling", "0/1 Jacobi scaling (solver backend); default 0", {"jacobi"}},
        {"nonmonotonic_steps",
         "0/1 non-monotonic steps (solver backend); default 1",
         {"nonmonotonic"}}},
       {"ceres", "ceres:dogleg", "ceres:lm,backend=solver"},
       [](EngineSpecReader& s, SolverOptions o) {
         CeresOptions c;
         if (auto w = s.word({"lm", "dogleg"}); w && *w == "dogleg") {
           c.method = CeresOptions::Method::kDogleg;
         }
         if (auto v = s.choice("backend", {"auto", "tiny", "solver"})) {
           c.backend = *v == "auto"   ? CeresOptions::Backend::kAuto
                       : *v == "tiny" ? CeresOptions::Backend::kTinySolver
                                      : CeresOptions::Backend::kSolver;
         }
         if (auto v = s.number("function_tolerance")) c.function_tolerance = *v;
         if (auto v = s.number("gradient_tolerance")) c.gradient_tolerance = *v;
         if (auto v = s.boolean("jacobi_scaling")) c.jacobi_scaling = *v;
         if (auto v = s.boolean("nonmonotonic_steps")) c.nonmonotonic_steps = *v;
         return std::make_unique<CeresEngine<N>>(c, std::move(o));
       }});
  add({"nlopt",
       "NLopt minimisation of 1/2 |F|^2 (bounds through the C++ API)",
       {{"<ALGORITHM>",
         "any NLopt name, e.g. LN_BOBYQA (default), LN_COBYLA, LD_SLSQP, "
         "LD_LBFGS, GN_DIRECT_L"},
        {"relative_step_tolerance",
         "relative step tolerance (NLopt's xtol_rel); default off",
         {"xtol_rel"}},
        {"initial_step", "first step of derivative-free algorithms"}},
       {"nlopt:LN_BOBYQA", "nlopt:LD_SLSQP"},
       [](EngineSpecReader& s, SolverOptions o) {
         NloptOptions n;
         if (auto w = s.word()) n.algorithm = *w;
         if (auto v = s.number("relative_step_tolerance")) n.relative_step_tolerance = *v;
         if (auto v = s.number("initial_step")) n.initial_step = *v;
         return std::make_unique<NloptEngine<N>>(n, std::move(o));
       }});
}

}  // namespace nlobs
