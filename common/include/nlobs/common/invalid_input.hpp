#pragma once
// The one exception every layer throws for bad input: a dimension mismatch, a non-finite
// value, an invalid option, a model parameter outside its domain. It lives below the layers
// (models and solvers both throw it, and neither depends on the other).
#include <stdexcept>
#include <string>

namespace nlobs {

// The message names the offending option or component and its value.
class InvalidInput : public std::invalid_argument {
 public:
  explicit InvalidInput(const std::string& what) : std::invalid_argument(what) {}
};

}  // namespace nlobs
