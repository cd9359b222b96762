#include "nlobs/models/modified_chua.hpp"

#include <numbers>
#include <sstream>

namespace nlobs {
namespace {

void require(bool ok, const char* name, double value, const char* requirement) {
  if (!ok) {
    std::ostringstream os;
    os << "ModifiedChuaParameters::" << name << " = " << value << " is invalid: " << requirement;
    throw InvalidInput(os.str());
  }
}

}  // namespace

ModifiedChua::ModifiedChua(ModifiedChuaParameters parameters)
    : p_(parameters), k_(std::numbers::pi / (2.0 * parameters.a)) {
  require(std::isfinite(p_.alpha), "alpha", p_.alpha, "must be finite");
  require(std::isfinite(p_.beta), "beta", p_.beta, "must be finite");
  require(std::isfinite(p_.a) && p_.a != 0.0, "a", p_.a, "must be finite and non-zero");
  require(std::isfinite(p_.b), "b", p_.b, "must be finite");
  require(std::isfinite(p_.d), "d", p_.d, "must be finite");
}

}  // namespace nlobs
