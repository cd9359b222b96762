#pragma once
// Forwarding header, kept for one release (docs/observers.md, "Header layout"): include
// "nlobs/observers/core/eigen_scalar.hpp" instead.
#include "nlobs/observers/core/eigen_scalar.hpp"
