#pragma once
// Forwarding header, kept for one release (docs/observers.md, "Header layout"): include
// "nlobs/observers/baselines/baselines.hpp" instead.
#include "nlobs/observers/baselines/baselines.hpp"
