#include "list_command.hpp"

#include <ostream>
#include <stdexcept>
#include <string>

#include "nlobs/common/printable.hpp"
#include "nlobs/reference/problem_suite.hpp"
#include "nlobs/registry/model_registry.hpp"
#include "nlobs/registry/observer_types.hpp"
#include "nlobs/registry/problem_sets.hpp"
#include "nlobs/runs/scenario.hpp"
#include "nlobs/solvers/engine_registry.hpp"
#include "solve_chua_window.hpp"

namespace nlobs::cli {
namespace {

// "depth (alias m)": a key and the older names it is also given by.
std::string with_aliases(const EngineOptionInfo& option) {
  std::string text = option.key;
  for (std::size_t i = 0; i < option.aliases.size(); ++i) {
    text += (i == 0 ? " (alias " : ", ") + option.aliases[i];
  }
  return option.aliases.empty() ? text : text + ")";
}

}  // namespace

void print_list(const std::string& what, std::ostream& out) {
  const bool all = what.empty();
  if (!all && what != "engines" && what != "models" && what != "observers" && what != "scenarios" &&
      what != "problems") {
    throw std::invalid_argument("nothing to list under '" + what +
                                "'; valid: models, engines, observers, scenarios, problems");
  }
  if (all || what == "models") {
    out << "models (JSON: {\"name\", \"parameters\", \"scheme\": euler|rk4|dopri5|sdirk3, "
           "\"step\", \"substeps\": 1.."
        << DiscretizationOptions::kMostSubsteps
        << ", \"absolute_tolerance\", \"relative_tolerance\"}):\n";
    for (const ModelEntry* m : model_registry().entries()) {
      out << "  " << m->name << " — " << m->description << '\n';
      out << "      " << m->states << " states, " << m->inputs << " inputs, " << m->outputs
          << " outputs; T = " << m->default_step << ", " << scheme_name(m->default_scheme);
      if (m->default_substeps != 1) out << ", " << m->default_substeps << " substeps";
      out << "; observers:";
      for (const auto& f : m->families) out << ' ' << f;
      const std::string source = model_registry().source(m->name);
      if (source != "built-in") out << "; from " << source;
      out << '\n';
      for (const KeyInfo& p : m->parameters) {
        out << "      " << p.key << " = " << p.default_value << ": " << p.meaning << '\n';
      }
    }
  }
  if (all || what == "observers") {
    out << "observer types (scenario \"observers\" entries: {\"type\": NAME, key: value, ...}):\n";
    const ObserverTypeRegistry& types = observer_type_registry();
    for (const ObserverTypeEntry* t : types.entries()) {
      out << "  " << t->name << " — " << t->description;
      if (!t->condition.empty()) out << "; models: " << t->condition;
      const std::string source = types.source(t->name);
      if (source != "built-in") out << "; from " << source;
      out << '\n';
      for (const KeyInfo& k : t->keys) {
        out << "      " << k.key << ": " << k.meaning;
        if (!k.default_value.empty()) out << " (default " << k.default_value << ")";
        out << '\n';
      }
    }
  }
  if (all || what == "scenarios") {
    out << "scenarios (nlobs run NAME, or a JSON file):\n";
    for (const auto& s : builtin_scenarios()) out << "  " << s << '\n';
  }
  if (all || what == "problems") {
    out << "problem sets (nlobs suite SET[:n=K]; nlobs solve SET/NAME[:n=K]):\n";
    const auto& sets = problem_set_registry();
    for (const ProblemSetEntry* set : sets.entries()) {
      out << "  " << set->name << " — " << set->description
          << "; solved at |D_f F|2 <= " << set->solved_threshold
          << " (D_f = diag(f_scale) of a scaled problem, else the identity)";
      const std::string source = sets.source(set->name);
      if (source != "built-in") out << "; from " << source;
      if (set->problems_of_size) out << "; any size (" << set->name << ":n=K)";
      out << '\n';
      try {
        for (const TestProblem& p : build_problem_set(*set)) {
          out << "      " << p.name << ":n=" << p.size() << (p.fixed_point ? " (x = G(x))" : "")
              << "; starts";
          for (const ProblemStart& st : p.starts) out << ' ' << st.label;
          if (p.lower.size() || p.upper.size()) out << "; bounded";
          if (p.u_scale.size() || p.f_scale.size()) {
            out << "; scaled (" << (p.u_scale.size() ? "u_scale" : "")
                << (p.u_scale.size() && p.f_scale.size() ? ", " : "")
                << (p.f_scale.size() ? "f_scale" : "") << ")";
          }
          if (!p.solutions.empty()) out << "; " << p.solutions.size() << " known solution(s)";
          if (!p.description.empty()) out << "; " << p.description;
          out << '\n';
        }
      } catch (...) {  // a user's set that cannot be built (whatever it threw): say so, go on
        out << "      (cannot be built: " << current_exception_text(1000) << ")\n";
      }
    }
  }
  if (!all && what != "engines") return;
  out << "engines (spec: name[:word][,key=value...]):\n";
  for (const auto& e : EngineRegistry<Dynamic>::global().entries()) {
    out << "  " << e.name << " — " << e.description;
    const std::string source = EngineRegistry<Dynamic>::global().source(e.name);
    if (source != "built-in") out << "; from " << source;
    out << '\n';
    for (const auto& o : e.options)
      out << "      " << with_aliases(o) << ": " << o.description << '\n';
    if (!e.without_common.empty()) {
      out << "      not taken of the options of every engine:";
      for (const auto& key : e.without_common) out << ' ' << key;
      out << '\n';
    }
    out << "      e.g.";
    for (const auto& x : e.examples) out << ' ' << x;
    out << '\n';
  }
  out << "  options of every engine (unless an engine says otherwise):";
  for (const auto& o : EngineRegistry<Dynamic>::global().common_options()) {
    out << "\n      " << with_aliases(o) << ": " << o.description;
  }
  out << "\nreference solvers (same run, for comparison):\n  solve chua-window:";
  for (const auto& r : reference_names()) out << ' ' << r;
  out << "\n  suite SET and solve SET/NAME (default):";
  for (const auto& r : reference::reference_suite_solvers()) out << ' ' << r;
  out << "\n  suite SET and solve SET/NAME (accepted):";
  for (const auto& r : reference::all_reference_solvers()) out << ' ' << r;
  out << '\n';
}

}  // namespace nlobs::cli
