#pragma once
// Forwarding header, kept for one release (docs/observers.md, "Header layout"): include
// "nlobs/observers/baselines/finite_difference_observer.hpp" instead.
#include "nlobs/observers/baselines/finite_difference_observer.hpp"
