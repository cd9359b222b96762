#pragma once
// Forwarding header, kept for one release (docs/observers.md, "Header layout"): include
// "nlobs/observers/core/sampled_data.hpp" instead.
#include "nlobs/observers/core/sampled_data.hpp"
