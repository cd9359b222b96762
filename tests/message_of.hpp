#pragma once
// The one helper the tests read refusals with, light enough for any test file.
#include <string>

#include "nlobs/common/invalid_input.hpp"

namespace nlobs::test {

// The message of the InvalidInput that f throws, or "<no exception>".
template <typename F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const InvalidInput& e) {
    return e.what();
  }
  return "<no exception>";
}

}  // namespace nlobs::test
