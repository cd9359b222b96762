#pragma once
// Forwarding header, kept for one release (docs/observers.md, "Header layout"): include
// "nlobs/observers/core/option_checks.hpp" instead.
#include "nlobs/observers/core/option_checks.hpp"
