// NloptOptions: validation, description and spec reading (nlopt_engine.hpp).
#include <algorithm>
#include <cmath>

#include "nlobs/common/invalid_input.hpp"
#include "nlobs/solvers/box_bounds.hpp"
#include "nlobs/solvers/nlopt_engine.hpp"
#include "nlobs/solvers/options_validation.hpp"

namespace nlobs {

void NloptOptions::validate() const {
  // Looked up here: nlopt_algorithm_from_string returns -1, not an enumerator, for an unknown name.
  const std::vector<std::string> names = nlopt_algorithm_names();
  if (algorithm.empty() || std::find(names.begin(), names.end(), algorithm) == names.end()) {
    std::string valid;
    for (const std::string& a : names) valid += (valid.empty() ? "" : ", ") + a;
    throw InvalidInput("NloptOptions::algorithm = '" + algorithm +
                       "' is not an NLopt algorithm; valid: " + valid);
  }
  detail::validate_box("NloptOptions", lower_bounds, upper_bounds);
  const bool global = algorithm[0] == 'G';
  if (global && (lower_bounds.size() == 0 || upper_bounds.size() == 0 ||
                 !lower_bounds.allFinite() || !upper_bounds.allFinite())) {
    throw InvalidInput("NloptOptions: global algorithm " + algorithm +
                       " needs finite lower_bounds and upper_bounds");
  }
  require_option(relative_step_tolerance >= 0.0 && std::isfinite(relative_step_tolerance),
                 "NloptOptions", "relative_step_tolerance", relative_step_tolerance,
                 "must be finite and >= 0 (0 = off)");
  if (initial_step) {
    require_option(*initial_step > 0.0 && std::isfinite(*initial_step), "NloptOptions",
                   "initial_step", *initial_step, "must be finite and > 0");
  }
}

EngineDescription NloptOptions::describe() {
  return {"nlopt",
          "NLopt minimisation of 1/2 |F|^2 (bounds through the C++ API)",
          {{"<ALGORITHM>",
            "any NLopt name, e.g. LN_BOBYQA (default), LN_COBYLA, LD_SLSQP, LD_LBFGS, "
            "GN_DIRECT_L"},
           {"relative_step_tolerance",
            "relative step tolerance (NLopt's xtol_rel); default off",
            {"xtol_rel"}},
           {"initial_step", "first step of derivative-free algorithms"}},
          {"nlopt:LN_BOBYQA", "nlopt:LD_SLSQP"}};
}

void NloptOptions::read(EngineSpecReader& spec) {
  if (auto w = spec.word()) algorithm = *w;
  if (auto v = spec.number("relative_step_tolerance")) relative_step_tolerance = *v;
  if (auto v = spec.number("initial_step")) initial_step = *v;
}

}  // namespace nlobs
