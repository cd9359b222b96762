#pragma once
// Forwarding header, kept for one release (docs/observers.md, "Header layout"): include
// "nlobs/observers/core/any_model.hpp" instead.
#include "nlobs/observers/core/any_model.hpp"
