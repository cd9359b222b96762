#pragma once
// Forwarding header, kept for one release (docs/observers.md, "Header layout"): include
// "nlobs/models/embedded_forms.hpp" instead.
#include "nlobs/models/embedded_forms.hpp"
