#include "nlobs/observers/core/option_checks.hpp"

#include <Eigen/Cholesky>
#include <array>
#include <charconv>
#include <cmath>
#include <sstream>

namespace nlobs::detail {
// 0.1, not 0.10000000000000001.
std::string option_value(double value) {
  std::array<char, 32> text{};
  const auto result = std::to_chars(text.data(), text.data() + text.size(), value);
  return std::string(text.data(), result.ptr);
}

void invalid_option(const char* who, const char* field, const std::string& condition,
                    const std::string& got) {
  throw InvalidInput(std::string(who) + "::" + field + " must " + condition + " (got " + got + ")");
}

void require_name(const char* who, const std::string& name) {
  if (name.empty()) invalid_option(who, "name", "not be empty", "\"\"");
}

void require_finite(const char* who, const char* field, const Eigen::MatrixXd& m) {
  if (m.size() > 0 && m.allFinite()) return;
  std::ostringstream os;
  os << m.rows() << "x" << m.cols();
  if (m.size() > 0 && m.size() <= 16) os << ": [" << m.reshaped().transpose() << "]";
  invalid_option(who, field, "be given, every entry finite", os.str());
}

void require_positive(const char* who, const char* field, double value) {
  if (!(value > 0.0) || !std::isfinite(value)) {
    invalid_option(who, field, "be finite and > 0", option_value(value));
  }
}

void require_non_negative(const char* who, const char* field, double value) {
  if (!(value >= 0.0) || !std::isfinite(value)) {
    invalid_option(who, field, "be finite and >= 0", option_value(value));
  }
}

void require_at_least(const char* who, const char* field, double value, double lower) {
  if (!(value >= lower) || !std::isfinite(value)) {
    invalid_option(who, field, "be finite and >= " + option_value(lower), option_value(value));
  }
}

void require_at_least(const char* who, const char* field, long value, long lower) {
  if (value < lower) {
    invalid_option(who, field, "be >= " + std::to_string(lower), std::to_string(value));
  }
}

void require_size(const char* who, const char* field, const Eigen::VectorXd& v, Eigen::Index size) {
  if (v.size() != size) {
    invalid_option(who, field, "have " + std::to_string(size) + " entries",
                   std::to_string(v.size()));
  }
}

void require_shape(const char* who, const char* field, const Eigen::MatrixXd& m, Eigen::Index rows,
                   Eigen::Index cols) {
  if (m.rows() == rows && m.cols() == cols && m.allFinite()) return;
  std::ostringstream want, got;
  want << "be a finite " << rows << "x" << cols << " matrix";
  got << m.rows() << "x" << m.cols() << (m.allFinite() ? "" : ", not all finite");
  invalid_option(who, field, want.str(), got.str());
}

void require_covariance(const char* who, const char* field, const Eigen::MatrixXd& m,
                        Definiteness definiteness) {
  if (m.size() == 0) return;
  std::ostringstream got;
  got << m.rows() << "x" << m.cols();
  // Square and finite first: the factorisation asserts (or reads out of bounds) otherwise.
  const auto fail = [&](const char* condition, const char* what) {
    got << what;
    invalid_option(who, field, condition, got.str());
  };
  if (m.rows() != m.cols()) fail("be square", "");
  if (!m.allFinite()) fail("be finite", ", not all entries finite");
  if (!m.isApprox(m.transpose())) fail("be symmetric", ", not symmetric");
  // A diagonal matrix (the usual Q, R, P0) is read off in O(n²); at n = 3200 the factorisations
  // below took seconds.
  if (m.isDiagonal(0.0)) {
    const bool positive = (m.diagonal().array() > 0.0).all();
    const bool non_negative = (m.diagonal().array() >= 0.0).all();
    if (definiteness == Definiteness::kDefinite && !positive) {
      fail("be positive definite", ", not positive definite");
    }
    if (!non_negative) fail("be positive semi-definite", ", a negative eigenvalue");
    return;
  }
  if (definiteness == Definiteness::kDefinite) {
    const Eigen::LLT<Eigen::MatrixXd> llt(m);
    if (llt.info() != Eigen::Success) fail("be positive definite", ", not positive definite");
    return;
  }
  if (Eigen::LLT<Eigen::MatrixXd>(m).info() == Eigen::Success) return;  // definite: blocked, fast
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(m);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) {
    fail("be positive semi-definite", ", a negative eigenvalue");
  }
}

Eigen::MatrixXd covariance_or_default(const char* who, const char* field, const Eigen::MatrixXd& m,
                                      Eigen::Index size, double default_scale) {
  if (m.size() == 0) return default_scale * Eigen::MatrixXd::Identity(size, size);
  require_shape(who, field, m, size, size);
  return m;
}

}  // namespace nlobs::detail
