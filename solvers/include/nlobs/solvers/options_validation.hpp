#pragma once
// The one refusal of an option's validate(): "NewtonOptions::backtrack_factor = 2 is invalid:
// must lie in (0, 1)". An engine's constructor calls its options' validate(), so an engine never
// holds options it refused (LBFGS++'s check_param()); a user's engine can do the same.
#include <string_view>

namespace nlobs {

// Throws InvalidInput "<owner>::<field> = <value> is invalid: <requirement>" unless `ok`.
void require_option(bool ok, std::string_view owner, std::string_view field, double value,
                    std::string_view requirement);

}  // namespace nlobs
