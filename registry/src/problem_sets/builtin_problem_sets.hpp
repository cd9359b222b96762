#pragma once
// The built-in problem sets in their documented order: chua-window, mgh, bounded.
#include "nlobs/registry/problem_sets.hpp"

namespace nlobs::detail {
void add_builtin_problem_sets(NamedRegistry<ProblemSetEntry>& registry);
}  // namespace nlobs::detail
