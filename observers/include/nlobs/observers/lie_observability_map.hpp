#pragma once
// Forwarding header, kept for one release (docs/observers.md, "Header layout"): include
// "nlobs/observers/high_gain/lie_observability_map.hpp" instead.
#include "nlobs/observers/high_gain/lie_observability_map.hpp"
