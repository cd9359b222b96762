#pragma once
// Forwarding header, kept for one release (docs/observers.md, "Header layout"): include
// "nlobs/observers/mvt/mvt_beta.hpp" instead.
#include "nlobs/observers/mvt/mvt_beta.hpp"
