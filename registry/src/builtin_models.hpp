#pragma once
// The built-in models in their documented order, split over three files to keep each
// compilation short.
#include "nlobs/registry/model_registry.hpp"

namespace nlobs::detail {
void add_builtin_models_a(ModelRegistry& registry);
void add_builtin_models_b(ModelRegistry& registry);
void add_builtin_models_c(ModelRegistry& registry);
}  // namespace nlobs::detail
