#pragma once
// Forwarding header, kept for one release (docs/observers.md, "Header layout"): include
// "nlobs/observers/modulating/modulating_kernel.hpp" instead.
#include "nlobs/observers/modulating/modulating_kernel.hpp"
