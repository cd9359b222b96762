#pragma once
// Forwarding header, kept for one release (docs/observers.md, "Header layout"): include
// "nlobs/observers/high_gain/taylor_observability_map.hpp" instead.
#include "nlobs/observers/high_gain/taylor_observability_map.hpp"
