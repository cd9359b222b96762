#pragma once
// Moved to nlobs/common/named_registry.hpp, where the engine registry uses it too; this path is
// kept for one release.
#include "nlobs/common/named_registry.hpp"
