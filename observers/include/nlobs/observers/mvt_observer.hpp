#pragma once
// Forwarding header, kept for one release (docs/observers.md, "Header layout"): include
// "nlobs/observers/mvt/mvt_observer.hpp" instead.
#include "nlobs/observers/mvt/mvt_observer.hpp"
