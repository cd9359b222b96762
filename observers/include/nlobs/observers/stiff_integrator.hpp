#pragma once
// Forwarding header, kept for one release (docs/observers.md, "Header layout"): include
// "nlobs/observers/core/stiff_integrator.hpp" instead.
#include "nlobs/observers/core/stiff_integrator.hpp"
