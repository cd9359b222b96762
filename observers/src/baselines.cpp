#include "nlobs/observers/baselines.hpp"

#include <Eigen/Cholesky>
#include <cmath>
#include <sstream>

namespace nlobs {
namespace {

void require_name(const char* who, const std::string& name) {
  if (name.empty()) throw InvalidInput(std::string(who) + "::name must not be empty");
}

void require_finite(const char* who, const char* field, const Eigen::MatrixXd& m) {
  if (m.size() > 0 && m.allFinite()) return;
  std::ostringstream os;
  os << who << "::" << field << " must be given, every entry finite (got " << m.rows() << "x"
     << m.cols();
  if (m.size() > 0) os << ": [" << m.reshaped().transpose() << "]";
  os << ")";
  throw InvalidInput(os.str());
}

// An optional covariance: empty (the default is used), or square, finite, symmetric and
// positive semi-definite.
void require_covariance(const char* field, const Eigen::MatrixXd& m) {
  if (m.size() == 0) return;
  // Square and finite first: the factorisation asserts (or reads out of bounds) otherwise.
  if (m.rows() == m.cols() && m.allFinite() && m.isApprox(m.transpose())) {
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(m);
    if (ldlt.info() == Eigen::Success && ldlt.isPositive()) return;
  }
  std::ostringstream os;
  os << "EkfOptions::" << field << " (" << m.rows() << "x" << m.cols()
     << ") must be square, finite, symmetric positive semi-definite";
  throw InvalidInput(os.str());
}

}  // namespace

void LuenbergerOptions::validate() const {
  require_name("LuenbergerOptions", name);
  require_finite("LuenbergerOptions", "initial_estimate", initial_estimate);
  require_finite("LuenbergerOptions", "gain", gain);
}

void SlidingModeOptions::validate() const {
  require_name("SlidingModeOptions", name);
  require_finite("SlidingModeOptions", "initial_estimate", initial_estimate);
  require_finite("SlidingModeOptions", "q", q);
  require_finite("SlidingModeOptions", "r", r);
  if (!(gamma > 0.0) || !std::isfinite(gamma)) {
    std::ostringstream os;
    os << "SlidingModeOptions::gamma = " << gamma << " must be finite and > 0";
    throw InvalidInput(os.str());
  }
}

void EkfOptions::validate() const {
  require_name("EkfOptions", name);
  require_finite("EkfOptions", "initial_estimate", initial_estimate);
  require_covariance("process_covariance Q", process_covariance);
  require_covariance("measurement_covariance R", measurement_covariance);
  require_covariance("initial_covariance P0", initial_covariance);
}

}  // namespace nlobs
