// AndersonOptions: validation, description and spec reading (accelerators/anderson.hpp).
#include "nlobs/solvers/accelerators/anderson.hpp"

namespace nlobs {

void AndersonOptions::validate() const {
  require_option(depth >= 0 && depth <= kMaxDepth, "AndersonOptions", "depth", depth,
                 "must be in 0..1000");
  require_option(condition_limit > 1.0, "AndersonOptions", "condition_limit", condition_limit,
                 "must be > 1");
  require_option(damping > 0.0 && damping <= 1.0, "AndersonOptions", "damping", damping,
                 "must lie in (0, 1]");
}

EngineDescription AndersonOptions::describe() {
  return {"anderson",
          "Anderson acceleration (type II)",
          {{"depth", "m >= 0, the differences kept; default 3", {"m"}},
           {"damping", "beta in (0, 1]; default 1"},
           {"condition_limit",
            "drop old columns above this condition estimate; default 1e8",
            {"cond"}}},
          {"anderson", "anderson:depth=3,damping=0.5"}};
}

void AndersonOptions::read(EngineSpecReader& spec) {
  if (auto v = spec.integer("depth", 0, kMaxDepth)) depth = *v;
  if (auto v = spec.number("damping")) damping = *v;
  if (auto v = spec.number("condition_limit")) condition_limit = *v;
}

}  // namespace nlobs
