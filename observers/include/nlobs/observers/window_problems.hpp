#pragma once
// Forwarding header, kept for one release (docs/observers.md, "Header layout"): include
// "nlobs/observers/window/window_problems.hpp" instead.
#include "nlobs/observers/window/window_problems.hpp"
