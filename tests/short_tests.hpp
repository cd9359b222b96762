#pragma once
// NLOBS_SHORT_TESTS=1 (set by ctest in the sanitizer build, `make sanitize`): tests that need
// long simulations run a shorter horizon there, with the same assertions. A test that uses it
// says which horizon it runs and why the shorter one still covers what it asserts.
#include <cstdlib>
#include <string>

namespace nlobs::test {

inline bool short_tests() {
  const char* v = std::getenv("NLOBS_SHORT_TESTS");
  return v != nullptr && std::string(v) == "1";
}

}  // namespace nlobs::test
