#include "nlobs/observers/core/chi_squared.hpp"

#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <sstream>

#include "nlobs/common/invalid_input.hpp"

namespace nlobs {

double chi_squared_quantile(double dof, double probability) {
  if (!(dof > 0.0) || !std::isfinite(dof) || !(probability > 0.0 && probability < 1.0)) {
    std::ostringstream os;
    os << "chi_squared_quantile: dof = " << dof
       << " must be finite and > 0, probability = " << probability << " in (0, 1)";
    throw InvalidInput(os.str());
  }
  return boost::math::quantile(boost::math::chi_squared_distribution<double>(dof), probability);
}

}  // namespace nlobs
