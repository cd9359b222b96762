#pragma once
// Forwarding header, kept for one release (docs/observers.md, "Header layout"): include
// "nlobs/observers/high_gain/high_gain_observer.hpp" instead.
#include "nlobs/observers/high_gain/high_gain_observer.hpp"
