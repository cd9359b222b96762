#pragma once
// The message of the std::invalid_argument a call throws (InvalidInput is one), for tests of
// refusals by the reference solvers (KINSOL, PETSc), which throw std::invalid_argument.
#include <stdexcept>
#include <string>

namespace nlobs::test {

// "<accepted>" when f throws nothing; another exception propagates.
template <typename F>
std::string invalid_argument_of(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "<accepted>";
}

}  // namespace nlobs::test
