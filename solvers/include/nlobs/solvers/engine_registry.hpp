#pragma once
// Engines by name: EngineRegistry<N>::global().create("anderson:m=3,damping=0.5").
// Every built-in engine is registered; a user registers their own under its own name with
// add(). Options common to all engines: tol (step tolerance), ftol (residual tolerance),
// max_iter, max_evals.
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "nlobs/solvers/ceres_engine.hpp"
#include "nlobs/solvers/engine_spec.hpp"
#include "nlobs/solvers/fixed_point_engines.hpp"
#include "nlobs/solvers/newton_engine.hpp"
#include "nlobs/solvers/nlopt_engine.hpp"

namespace nlobs {

template <int N = Dynamic>
class EngineRegistry {
 public:
  using Factory = std::function<std::unique_ptr<Engine<N>>(EngineSpecReader&, SolverOptions)>;
  struct Entry {
    std::string name;
    std::string description;
    std::vector<EngineOptionInfo> options;  // engine-specific; the common ones are added
    std::vector<std::string> examples;      // spec strings shown by `nlobs list engines`
    Factory make;
  };

  // The process-wide registry, with every built-in engine.
  static EngineRegistry& global() {
    static EngineRegistry registry = with_builtins();
    return registry;
  }

  static const std::vector<EngineOptionInfo>& common_options() {
    static const std::vector<EngineOptionInfo> common = {
        {"tol", "step tolerance, max norm; default 1e-8"},
        {"ftol", "residual tolerance ‖F‖∞; default off"},
        {"max_iter", "maximum iterations; default 10000"},
        {"max_evals", "maximum function evaluations; default 100000"}};
    return common;
  }

  // Throws InvalidInput if the name is empty, malformed or taken, or the factory is empty.
  void add(Entry entry) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (entry.name.empty() || entry.name.find_first_of(":,=") != std::string::npos) {
      throw InvalidInput("engine name '" + entry.name + "' is empty or contains ':', ',' or '='");
    }
    if (entries_.count(entry.name)) {
      throw InvalidInput("an engine named '" + entry.name + "' is already registered");
    }
    if (!entry.make) throw InvalidInput("engine '" + entry.name + "' has no factory");
    const std::string name = entry.name;
    entries_.emplace(name, std::move(entry));
  }

  bool contains(const std::string& name) const {
    std::lock_guard<std::mutex> lock(mutex_);
    return entries_.count(name) > 0;
  }

  std::vector<Entry> entries() const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<Entry> out;
    for (const auto& [name, e] : entries_) out.push_back(e);
    return out;
  }

  std::vector<std::string> names() const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<std::string> out;
    for (const auto& [name, e] : entries_) out.push_back(name);
    return out;
  }

  // Builds the engine a spec names; `base` supplies stop criteria the spec does not set.
  // Throws InvalidInput for an unknown name (listing the valid ones) or option.
  std::unique_ptr<Engine<N>> create(std::string_view spec_text, SolverOptions base = {}) const {
    const EngineSpec spec = parse_engine_spec(spec_text);
    Factory make;
    std::vector<EngineOptionInfo> valid;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      auto it = entries_.find(spec.name);
      if (it == entries_.end()) {
        std::string list;
        for (const auto& [name, e] : entries_) list += (list.empty() ? "" : ", ") + name;
        throw InvalidInput("unknown engine '" + spec.name + "'; valid engines: " + list);
      }
      make = it->second.make;
      valid = it->second.options;
    }
    valid.insert(valid.end(), common_options().begin(), common_options().end());
    EngineSpecReader reader(spec, valid);
    if (auto v = reader.number("tol")) base.stop.step_tolerance = *v;
    if (auto v = reader.number("ftol")) base.stop.residual_tolerance = *v;
    if (auto v = reader.integer("max_iter")) base.stop.max_iterations = *v;
    if (auto v = reader.integer("max_evals")) base.stop.max_evaluations = *v;
    std::unique_ptr<Engine<N>> engine = make(reader, std::move(base));
    reader.finish();
    return engine;
  }

 private:
  static EngineRegistry with_builtins() {
    EngineRegistry r;
    r.add({"picard", "x <- G(x)", {}, {"picard"}, [](EngineSpecReader&, SolverOptions o) {
             return std::make_unique<PicardEngine<N>>(std::move(o));
           }});
    r.add({"aitken",
           "component-wise Aitken delta^2 of the Picard sequence",
           {},
           {"aitken"},
           [](EngineSpecReader&, SolverOptions o) {
             return std::make_unique<AitkenEngine<N>>(std::move(o));
           }});
    r.add({"steffensen",
           "Aitken restarted every three iterates",
           {},
           {"steffensen"},
           [](EngineSpecReader&, SolverOptions o) {
             return std::make_unique<SteffensenEngine<N>>(std::move(o));
           }});
    r.add({"anderson",
           "Anderson acceleration (type II)",
           {{"m", "depth >= 0; default 3"},
            {"damping", "beta in (0, 1]; default 1"},
            {"cond", "drop old columns above this condition estimate; default 1e8"}},
           {"anderson", "anderson:m=3,damping=0.5"},
           [](EngineSpecReader& s, SolverOptions o) {
             AndersonOptions a;
             if (auto v = s.integer("m")) a.depth = *v;
             if (auto v = s.number("damping")) a.damping = *v;
             if (auto v = s.number("cond")) a.condition_limit = *v;
             return std::make_unique<AndersonEngine<N>>(a, std::move(o));
           }});
    r.add({"newton",
           "Newton on F = G - x, any Jacobian source",
           {{"linesearch", "0/1 Armijo backtracking; default 0"},
            {"fd", "forward|central differences when no Jacobian; default central"}},
           {"newton", "newton:linesearch=1"},
           [](EngineSpecReader& s, SolverOptions o) {
             NewtonOptions n;
             if (auto v = s.boolean("linesearch")) n.line_search = *v;
             if (auto v = s.text("fd")) n.finite_difference = parse_fd(*v);
             return std::make_unique<NewtonEngine<N>>(n, std::move(o));
           }});
    r.add({"ceres",
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
    r.add({"nlopt",
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
    return r;
  }

  static FiniteDifference parse_fd(const std::string& v) {
    if (v == "central") return FiniteDifference::kCentral;
    if (v == "forward") return FiniteDifference::kForward;
    throw InvalidInput("newton: fd=" + v + " is not forward or central");
  }

  EngineRegistry() = default;
  EngineRegistry(EngineRegistry&& other) noexcept : entries_(std::move(other.entries_)) {}

  mutable std::mutex mutex_;
  std::map<std::string, Entry> entries_;
};

}  // namespace nlobs
