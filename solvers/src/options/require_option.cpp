#include <sstream>

#include "nlobs/common/invalid_input.hpp"
#include "nlobs/solvers/options_validation.hpp"

namespace nlobs::detail {

void require_option(bool ok, std::string_view owner, std::string_view field, double value,
                    std::string_view requirement) {
  if (ok) return;
  std::ostringstream os;
  os << owner << "::" << field << " = " << value << " is invalid: " << requirement;
  throw InvalidInput(os.str());
}

}  // namespace nlobs::detail
