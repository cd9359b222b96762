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
inline FiniteDifference parse_finite_difference(const char* engine, const std::string& v) {
  if (v == "central") return FiniteDifference::kCentral;
  if (v == "forward") return FiniteDifference::kForward;
  throw InvalidInput(std::string(engine) + ": fd=" + v + " is not forward or central");
}

// The keys linear=…, preconditioner=… and ordering=… of the engines with a sparse path, and
// their reading: the linear-solver spec, or nullopt when none is given.
inline constexpr const char* kLinearKeyHelp =
    "auto|dense|band-lu|sparse-lu|klu|umfpack|gmres|bicgstab: the linear solver of a problem with "
    "a sparse Jacobian; default auto (band-lu, klu, or umfpack from 20000 unknowns)";
inline constexpr const char* kPreconditionerKeyHelp =
    "none|jacobi|ilu0|ilut|boomeramg, with linear=gmres|bicgstab; default none";
inline constexpr const char* kOrderingKeyHelp =
    "amd|metis (nested dissection), with linear=umfpack; default amd";
inline std::optional<std::string> parse_linear_solver(const char* engine, EngineSpecReader& s,
                                                      std::string linear) {
  const std::optional<std::string> given = s.text("linear");
  if (given) linear = *given;
  const std::optional<std::string> preconditioner = s.text("preconditioner");
  if (preconditioner) {
    if (linear != "gmres" && linear != "bicgstab") {
      throw InvalidInput(std::string(engine) + ": preconditioner=" + *preconditioner +
                         " needs linear=gmres or linear=bicgstab");
    }
    linear += ":preconditioner=" + *preconditioner;
  }
  const std::optional<std::string> ordering = s.text("ordering");
  if (ordering) {
    if (linear != "umfpack") {
      throw InvalidInput(std::string(engine) + ": ordering=" + *ordering + " needs linear=umfpack");
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
       {{"m", "depth >= 0; default 3"},
        {"damping", "beta in (0, 1]; default 1"},
        {"cond", "drop old columns above this condition estimate; default 1e8"}},
       {"anderson", "anderson:m=3,damping=0.5"},
       [](EngineSpecReader& s, SolverOptions o) {
         AndersonOptions a;
         if (auto v = s.integer("m", 0, AndersonMixing<N>::kMaxDepth)) a.depth = *v;
         if (auto v = s.number("damping")) a.damping = *v;
         if (auto v = s.number("cond")) a.condition_limit = *v;
         return std::make_unique<AndersonEngine<N>>(a, std::move(o));
       }});
  add({"newton",
       "Newton on F = G - x, any Jacobian source",
       {{"linesearch", "0/1 Armijo backtracking; default 0"},
        {"trustregion", "0/1 dogleg trust region, a Jacobian every iterate; default 0"},
        {"fd", "forward|central differences when no Jacobian; default central"},
        {"linear", detail::kLinearKeyHelp},
        {"preconditioner", detail::kPreconditionerKeyHelp},
        {"ordering", detail::kOrderingKeyHelp},
        {"reuse",
         "1..1000 iterations one Jacobian (and its factorisation) serves: modified Newton "
         "(KINSOL: 10); default 1"}},
       {"newton", "newton:linesearch=1", "newton:trustregion=1",
        "newton:linesearch=1,linear=gmres,preconditioner=ilu0", "newton:linesearch=1,reuse=10"},
       [](EngineSpecReader& s, SolverOptions o) {
         NewtonOptions n;
         if (auto v = s.boolean("linesearch")) n.line_search = *v;
         if (auto v = s.boolean("trustregion")) n.trust_region = *v;
         if (auto v = s.integer("reuse", 1, 1000)) n.jacobian_reuse = *v;
         if (auto v = s.text("fd"))
           n.finite_difference = detail::parse_finite_difference("newton", *v);
         if (auto v = detail::parse_linear_solver("newton", s, n.linear_solver)) {
           n.linear_solver = *v;
         }
         return std::make_unique<NewtonEngine<N>>(n, std::move(o));
       }});
  add({"dogleg",
       "Powell's hybrid method (MINPACK hybrj): trust region, dogleg steps, Broyden updates",
       {{"scale",
         "none|jacobian: trust-region scaling D = I or Jacobian column norms "
         "(MINPACK mode 2|1); default none"},
        {"factor", "initial radius factor * |D x0|; default 100"},
        {"broyden", "0/1 Broyden updates between Jacobians; default 1"},
        {"fd", "forward|central differences when no Jacobian; default central"}},
       {"dogleg", "dogleg:scale=jacobian"},
       [](EngineSpecReader& s, SolverOptions o) {
         DoglegOptions d;
         if (auto v = s.text("scale")) {
           if (*v == "none")
             d.scaling = DoglegOptions::Scaling::kNone;
           else if (*v == "jacobian")
             d.scaling = DoglegOptions::Scaling::kJacobianColumns;
           else
             throw InvalidInput("dogleg: scale=" + *v + " is not none or jacobian");
         }
         if (auto v = s.number("factor")) d.initial_radius_factor = *v;
         if (auto v = s.boolean("broyden")) d.broyden_updates = *v;
         if (auto v = s.text("fd"))
           d.finite_difference = detail::parse_finite_difference("dogleg", *v);
         return std::make_unique<DoglegEngine<N>>(d, std::move(o));
       }});
  add({"broyden",
       "Broyden's good method: line search, Jacobian restarts, O(n^2) inverse updates (limited "
       "memory, O(k n), on a sparse Jacobian)",
       {{"backtracks", "step halvings before the Jacobian is renewed, 0..60; default 10"},
        {"updates", "updates before a fresh Jacobian regardless, 0 = off; default 0"},
        {"fd", "forward|central differences when no Jacobian; default central"},
        {"linear",
         "auto|dense|band-lu|sparse-lu|klu|umfpack: H0 = J^-1 of a problem with a sparse "
         "Jacobian by this direct solver, the updates kept as vectors (limited memory), or "
         "dense H; default auto"},
        {"ordering", detail::kOrderingKeyHelp},
        {"memory",
         "updates the limited-memory form keeps before a fresh Jacobian, 1..1000; "
         "default 20"}},
       {"broyden", "broyden:fd=forward,updates=20", "broyden:memory=50"},
       [](EngineSpecReader& s, SolverOptions o) {
         BroydenOptions b;
         if (auto v = s.integer("backtracks", 0, 60)) b.max_backtracks = *v;
         if (auto v = s.integer("updates", 0, 1 << 30)) b.max_updates = *v;
         if (auto v = s.integer("memory", 1, 1000)) b.memory = *v;
         if (auto v = s.text("preconditioner")) {
           throw InvalidInput("broyden: preconditioner=" + *v +
                              " does not apply: H0 is applied by a direct solver "
                              "(linear=auto|band-lu|sparse-lu|klu|umfpack)");
         }
         if (auto v = detail::parse_linear_solver("broyden", s, b.linear_solver)) {
           b.linear_solver = *v;
         }
         if (auto v = s.text("fd"))
           b.finite_difference = detail::parse_finite_difference("broyden", *v);
         return std::make_unique<BroydenEngine<N>>(b, std::move(o));
       }});
  add({"levenberg-marquardt",
       "Levenberg-Marquardt as MINPACK lmder (More's lambda and scaling), square or least "
       "squares",
       {{"scale", "none|jacobian: D = I or Jacobian column norms (More); default none"},
        {"factor", "initial radius factor * |D x0|; default 100"},
        {"geodesic", "0/1 geodesic acceleration (Transtrum-Sethna); default 0"},
        {"ftol", "relative reduction of |F|^2 (least squares); default 1e-10"},
        {"gtol", "cosine of F and the columns of J; default 1e-12"},
        {"fd", "forward|central differences when no Jacobian; default central"},
        {"linear",
         "auto|cholmod|dense: the step of a problem with a sparse Jacobian by CHOLMOD's sparse "
         "Cholesky of the normal equations, or dense QR; default auto (cholmod)"}},
       {"levenberg-marquardt", "levenberg-marquardt:geodesic=1",
        "levenberg-marquardt:scale=jacobian", "levenberg-marquardt:linear=dense"},
       [](EngineSpecReader& s, SolverOptions o) {
         LevenbergMarquardtOptions l;
         if (auto v = s.text("scale")) {
           if (*v == "jacobian")
             l.scale_by_jacobian_columns = true;
           else if (*v == "none")
             l.scale_by_jacobian_columns = false;
           else
             throw InvalidInput("levenberg-marquardt: scale=" + *v + " is not none or jacobian");
         }
         if (auto v = s.number("factor")) l.initial_radius_factor = *v;
         if (auto v = s.boolean("geodesic")) l.geodesic_acceleration = *v;
         if (auto v = s.number("ftol")) l.function_tolerance = *v;
         if (auto v = s.number("gtol")) l.gradient_tolerance = *v;
         if (auto v = s.text("fd")) {
           l.finite_difference = detail::parse_finite_difference("levenberg-marquardt", *v);
         }
         if (auto v = s.text("linear")) l.linear_solver = *v;
         return std::make_unique<LevenbergMarquardtEngine<N>>(l, std::move(o));
       }});
  add({"pseudo-transient",
       "pseudo-transient continuation (Kelley-Keyes): implicit Euler on a flow to the root, "
       "growing "
       "step",
       {{"flow", "residual|fixed-point: dx/dt = -F = x - G(x) or G(x) - x; default residual"},
        {"delta0", "initial pseudo time step, >= 2.22e-16 (machine epsilon); default 1e-2"},
        {"delta_max", "largest pseudo time step; default 1e12"},
        {"growth", "factor gamma >= 1 on the SER step update (PETSc: 1.1), <= 10; default 1"},
        {"fd", "forward|central differences when no Jacobian; default central"},
        {"linear", detail::kLinearKeyHelp},
        {"preconditioner", detail::kPreconditionerKeyHelp},
        {"ordering", detail::kOrderingKeyHelp}},
       {"pseudo-transient:flow=fixed-point", "pseudo-transient:flow=fixed-point,delta0=1e-4",
        "pseudo-transient:flow=fixed-point,linear=gmres,preconditioner=ilu0"},
       [](EngineSpecReader& s, SolverOptions o) {
         PseudoTransientOptions p;
         if (auto v = s.text("flow")) {
           if (*v == "fixed-point")
             p.flow = PseudoTransientOptions::Flow::kFixedPoint;
           else if (*v == "residual")
             p.flow = PseudoTransientOptions::Flow::kResidual;
           else
             throw InvalidInput("pseudo-transient: flow=" + *v + " is not residual or fixed-point");
         }
         if (auto v = s.number("delta0")) p.initial_pseudo_step = *v;
         if (auto v = s.number("delta_max")) p.max_pseudo_step = *v;
         if (auto v = s.number("growth")) p.pseudo_step_growth = *v;
         // δ_min follows a δ₀ below its default (δ₀ itself is checked by the engine: >= ε).
         if (p.min_pseudo_step > p.initial_pseudo_step) {
           p.min_pseudo_step =
               std::max(p.initial_pseudo_step, PseudoTransientOptions::kMinPseudoStep);
         }
         if (auto v = s.text("fd")) {
           p.finite_difference = detail::parse_finite_difference("pseudo-transient", *v);
         }
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
        {"dense_limit",
         "on a problem with a sparse Jacobian and more unknowns than this, skip the stages "
         "without a sparse path (dense n x n J), 0 = never; default 1000"}},
       {"auto", "auto:order=dogleg/levenberg-marquardt,from=best"},
       [](EngineSpecReader& s, SolverOptions o) {
         PolyalgorithmOptions p;
         if (auto v = s.text("from")) {
           if (*v == "best")
             p.restart_from_best = true;
           else if (*v == "start")
             p.restart_from_best = false;
           else
             throw InvalidInput("auto: from=" + *v + " is not best or start");
         }
         if (auto v = s.integer("shared_minimum", 0, 1000)) p.shared_minimum = *v;
         if (auto v = s.integer("dense_limit", 0, std::numeric_limits<int>::max())) {
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
        {"function_tol", "relative cost change; default 1e-10"},
        {"gradient_tol", "default 1e-12"},
        {"jacobi", "0/1 Jacobi scaling (solver backend); default 0"},
        {"nonmonotonic", "0/1 non-monotonic steps (solver backend); default 1"}},
       {"ceres", "ceres:dogleg", "ceres:lm,backend=solver"},
       [](EngineSpecReader& s, SolverOptions o) {
         CeresOptions c;
         if (auto w = s.word({"lm", "dogleg"}); w && *w == "dogleg") {
           c.method = CeresOptions::Method::kDogleg;
         }
         if (auto v = s.text("backend")) {
           if (*v == "auto")
             c.backend = CeresOptions::Backend::kAuto;
           else if (*v == "tiny")
             c.backend = CeresOptions::Backend::kTinySolver;
           else if (*v == "solver")
             c.backend = CeresOptions::Backend::kSolver;
           else
             throw InvalidInput("ceres: backend=" + *v + " is not auto, tiny or solver");
         }
         if (auto v = s.number("function_tol")) c.function_tolerance = *v;
         if (auto v = s.number("gradient_tol")) c.gradient_tolerance = *v;
         if (auto v = s.boolean("jacobi")) c.jacobi_scaling = *v;
         if (auto v = s.boolean("nonmonotonic")) c.nonmonotonic_steps = *v;
         return std::make_unique<CeresEngine<N>>(c, std::move(o));
       }});
  add({"nlopt",
       "NLopt minimisation of 1/2 |F|^2 (bounds through the C++ API)",
       {{"<ALGORITHM>",
         "any NLopt name, e.g. LN_BOBYQA (default), LN_COBYLA, LD_SLSQP, "
         "LD_LBFGS, GN_DIRECT_L"},
        {"xtol_rel", "relative step tolerance; default off"},
        {"initial_step", "first step of derivative-free algorithms"}},
       {"nlopt:LN_BOBYQA", "nlopt:LD_SLSQP"},
       [](EngineSpecReader& s, SolverOptions o) {
         NloptOptions n;
         if (auto w = s.word()) n.algorithm = *w;
         if (auto v = s.number("xtol_rel")) n.relative_step_tolerance = *v;
         if (auto v = s.number("initial_step")) n.initial_step = *v;
         return std::make_unique<NloptEngine<N>>(n, std::move(o));
       }});
}

}  // namespace nlobs
