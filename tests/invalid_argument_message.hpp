#pragma once
// The message a refusal carries, for the tests of refusals: message_of for nlobs' own
// (InvalidInput only: a test of it also checks the type), invalid_argument_of for the reference
// solvers' (KINSOL, PETSc), which throw std::invalid_argument (InvalidInput is one). Light
// enough for any test file.
#include <stdexcept>
#include <string>
#include <utility>

#include "nlobs/common/invalid_input.hpp"

namespace nlobs::test {

// The message of the `Exception` f throws, or `none` when it throws nothing; another exception
// propagates.
template <typename Exception, typename F>
std::string message_of_exception(F&& f, const char* none) {
  try {
    f();
  } catch (const Exception& e) {
    return e.what();
  }
  return none;
}

// The message of the InvalidInput that f throws, or "<no exception>".
template <typename F>
std::string message_of(F&& f) {
  return message_of_exception<InvalidInput>(std::forward<F>(f), "<no exception>");
}

// The message of the std::invalid_argument that f throws, or "<accepted>".
template <typename F>
std::string invalid_argument_of(F&& f) {
  return message_of_exception<std::invalid_argument>(std::forward<F>(f), "<accepted>");
}

}  // namespace nlobs::test
