// libFuzzer target: the `--data` CSV reader (nlobs/runs/measurements_file.hpp) on arbitrary bytes,
// for three model shapes, with and without late rows (--allow-late). Either it refuses the input
// with std::invalid_argument, or what it returns keeps the documented invariants; anything else (a
// crash, another exception, a broken invariant) is a finding. `make fuzz` runs it; docs/fuzzing.md
// says what it found.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <string>

#include "nlobs/runs/measurements_file.hpp"

namespace {

void check(bool invariant) {
  if (!invariant) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* bytes, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(bytes), size);
  constexpr Eigen::Index kShapes[][2] = {{1, 0}, {2, 1}, {3, 0}};  // outputs, inputs
  for (const auto& shape : kShapes) {
    for (const bool late_rows : {false, true}) {  // --allow-late: times may go back
      std::istringstream in(text);
      try {
        const nlobs::Measurements m =
            nlobs::parse_measurements_csv(in, "fuzz.csv", shape[0], shape[1], late_rows);
        check(m.steps() >= 1 && m.t.size() == m.steps() && m.y.rows() == shape[0] &&
              m.u.rows() == shape[1] && m.u.cols() == m.steps() && !m.has_truth());
        for (Eigen::Index k = 0; k < m.steps(); ++k) {
          check(std::isfinite(m.t[k]) && (late_rows || k == 0 || m.t[k] > m.t[k - 1]));
          for (Eigen::Index i = 0; i < m.y.rows(); ++i) check(!std::isinf(m.y(i, k)));  // or NaN
          check(m.u.col(k).allFinite());
        }
      } catch (const std::invalid_argument&) {
        // A refusal, with its file:line message: fine.
      }
    }
  }
  return 0;
}
