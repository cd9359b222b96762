#include <cmath>
#include <sstream>

#include "nlobs/common/invalid_input.hpp"
#include "nlobs/solvers/options_validation.hpp"

namespace nlobs {

void require_option(bool ok, std::string_view owner, std::string_view field, double value,
                    std::string_view requirement) {
  if (ok) return;
  std::ostringstream os;
  os << owner << "::" << field << " = ";
  // Integers exactly (a count of 2000000 is not "2e+06"), other values as the stream writes them.
  if (std::isfinite(value) && value == std::floor(value) && std::abs(value) < 1e15) {
    os << static_cast<long long>(value);
  } else {
    os << value;
  }
  os << " is invalid: " << requirement;
  throw InvalidInput(os.str());
}

}  // namespace nlobs
