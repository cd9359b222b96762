// PolyalgorithmOptions: validation, description and spec reading (polyalgorithm_engine.hpp).
#include <limits>
#include <string>

#include "nlobs/solvers/options_validation.hpp"
#include "nlobs/solvers/polyalgorithm_engine.hpp"

namespace nlobs {

void PolyalgorithmOptions::validate() const {
  require_option(shared_minimum >= 0, "PolyalgorithmOptions", "shared_minimum", shared_minimum,
                 "must be >= 0 (0 = off)");
  require_option(dense_stage_limit >= 0, "PolyalgorithmOptions", "dense_stage_limit",
                 static_cast<double>(dense_stage_limit), "must be >= 0 (0 = no limit)");
}

EngineDescription PolyalgorithmOptions::describe() {
  return {"auto",
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
          {"auto", "auto:order=dogleg/levenberg-marquardt,from=best"}};
}

void PolyalgorithmOptions::read(EngineSpecReader& spec) {
  if (auto v = spec.choice("from", {"start", "best"})) restart_from_best = *v == "best";
  if (auto v = spec.integer("shared_minimum", 0, 1000)) shared_minimum = *v;
  if (auto v = spec.integer("dense_stage_limit", 0, std::numeric_limits<int>::max())) {
    dense_stage_limit = *v;
  }
}

}  // namespace nlobs
