// The PETSc-free part of petsc_solver.hpp: names, their options and the status text. Built with
// or without PETSc.
#include <algorithm>
#include <cctype>
#include <stdexcept>
#include <string>
#include <vector>

#include "nlobs/reference/petsc_solver.hpp"
#include "petsc_option_rules.hpp"

namespace nlobs::reference {

using petsc_rules::lower_word;
using petsc_rules::validate_option;

std::string PetscSnesResult::status() const {
  if (budget_spent) return "max_evaluations";
  if (!error.empty() && reason == 0) return "petsc_error";
  if (reason > 0)
    return success                                 ? "converged"
           : reason_text.rfind("returned", 0) == 0 ? "non_finite"
                                                   : "residual_above_tolerance";
  std::string s = reason_name.empty() ? "snes_reason_" + std::to_string(reason) : reason_name;
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

bool PetscSnesSolver::is_name(const std::string& name) {
  return name.rfind("petsc:", 0) == 0;
}

std::vector<std::string> PetscSnesSolver::names() {
  return {"petsc:newtonls", "petsc:newtontr", "petsc:ngmres",
          "petsc:anderson", "petsc:qn",       "petsc:nrichardson"};
}

PetscSnesOptions PetscSnesSolver::parse_name(const std::string& name) {
  if (!is_name(name)) throw std::invalid_argument("'" + name + "' is not a petsc:TYPE name");
  PetscSnesOptions o;
  std::vector<std::string> parts;
  std::size_t from = 6;
  while (true) {
    const std::size_t colon = name.find(':', from);
    parts.push_back(name.substr(from, colon == std::string::npos ? colon : colon - from));
    if (colon == std::string::npos) break;
    from = colon + 1;
  }
  o.type = parts.front();
  if (o.type.empty() || !lower_word(o.type, 0)) {
    throw std::invalid_argument("'" + name +
                                "': the SNES type after petsc: is lower-case letters "
                                "and digits (petsc:newtonls)");
  }
  for (std::size_t i = 1; i < parts.size(); ++i) {
    const std::string& p = parts[i];
    const std::size_t eq = p.find('=');
    std::string key = p.substr(0, eq);
    std::string value = eq == std::string::npos ? "" : p.substr(eq + 1);
    if (eq != std::string::npos && value.empty()) {
      throw std::invalid_argument("'" + name + "': option " + key + "= has no value");
    }
    validate_option(key, value);
    o.options.emplace_back(std::move(key), std::move(value));
  }
  return o;
}

}  // namespace nlobs::reference
