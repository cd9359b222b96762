#pragma once
// Forwarding header, kept for one release (docs/observers.md, "Header layout"): include
// "nlobs/observers/window/output_window.hpp" instead.
#include "nlobs/observers/window/output_window.hpp"
