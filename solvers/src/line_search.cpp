// LineSearch's validation (line_search.hpp).
#include "nlobs/solvers/line_search.hpp"

#include "nlobs/solvers/options_validation.hpp"

namespace nlobs {

void LineSearch::validate() const {
  constexpr const char* kOwner = "LineSearch";
  require_option(kind == Kind::kBacktracking || kind == Kind::kFullStep, kOwner, "kind",
                 static_cast<double>(kind), "must be kBacktracking or kFullStep");
  require_option(sufficient_decrease > 0.0 && sufficient_decrease < 1.0, kOwner,
                 "sufficient_decrease", sufficient_decrease, "must lie in (0, 1)");
  require_option(shrink > 0.0 && shrink < 1.0, kOwner, "shrink", shrink, "must lie in (0, 1)");
  require_option(max_backtracks >= 0, kOwner, "max_backtracks", max_backtracks, "must be >= 0");
}

}  // namespace nlobs
