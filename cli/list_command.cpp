#include "list_command.hpp"

#include <ostream>
#include <stdexcept>

#include "nlobs/solvers/engine_registry.hpp"
#include "reference/mgh_suite.hpp"
#include "solve_chua_window.hpp"

namespace nlobs::cli {

void print_list(const std::string& what, std::ostream& out) {
  if (!what.empty() && what != "engines") {
    throw std::invalid_argument("nothing to list under '" + what + "'; valid: engines");
  }
  out << "engines (spec: name[:word][,key=value...]):\n";
  for (const auto& e : EngineRegistry<Dynamic>::global().entries()) {
    out << "  " << e.name << " — " << e.description << '\n';
    for (const auto& o : e.options) out << "      " << o.key << ": " << o.description << '\n';
    out << "      e.g.";
    for (const auto& x : e.examples) out << ' ' << x;
    out << '\n';
  }
  out << "  options of every engine:";
  for (const auto& o : EngineRegistry<Dynamic>::global().common_options()) {
    out << "\n      " << o.key << ": " << o.description;
  }
  out << "\nreference solvers (same run, for comparison):\n  solve chua-window:";
  for (const auto& r : reference_names()) out << ' ' << r;
  out << "\n  suite mgh:";
  for (const auto& r : reference::reference_suite_solvers()) out << ' ' << r;
  out << '\n';
}

}  // namespace nlobs::cli
