#include "builtin_problem_sets.hpp"

#include "nlobs/registry/problem_sets/bounded_set.hpp"
#include "nlobs/registry/problem_sets/chua_window_set.hpp"
#include "nlobs/registry/problem_sets/large_set.hpp"
#include "nlobs/registry/problem_sets/mgh_problems.hpp"
#include "nlobs/registry/problem_sets/published_set.hpp"

namespace nlobs::detail {

void add_builtin_problem_sets(NamedRegistry<ProblemSetEntry>& registry) {
  registry.add(chua_window_problem_set());
  registry.add(mgh_problem_set());
  registry.add(bounded_problem_set());
  registry.add(published_problem_set());
  registry.add(large_problem_set());
}

}  // namespace nlobs::detail
