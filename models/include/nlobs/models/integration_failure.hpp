#pragma once
// What an integrator throws when it cannot take the move it was asked for: an adaptive step
// that fell below its floor, a step budget spent, a Newton iteration that would not converge.
// Not InvalidInput — the call was well formed; the model left what the scheme can follow
// (usually a state far outside the model's range, or a stiff plant on an explicit scheme).
// Observers count it as a failed step; a simulation stops with it.
#include <stdexcept>
#include <string>

namespace nlobs {

class IntegrationFailure : public std::runtime_error {
 public:
  explicit IntegrationFailure(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace nlobs
