#pragma once
// Forwarding header, kept for one release (docs/observers.md, "Header layout"): include
// "nlobs/models/modulating_forms.hpp" instead.
#include "nlobs/models/modulating_forms.hpp"
