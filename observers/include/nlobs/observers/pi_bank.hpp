#pragma once
// Forwarding header, kept for one release (docs/observers.md, "Header layout"): include
// "nlobs/observers/pi/pi_bank.hpp" instead.
#include "nlobs/observers/pi/pi_bank.hpp"
