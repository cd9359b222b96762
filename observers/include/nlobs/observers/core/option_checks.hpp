#pragma once
// The checks every XOptions::validate() is made of, so that all observers word a bad option the
// same way: "<Who>::<field> must <condition> (got <value>)", thrown as InvalidInput. Options
// validate what they alone can tell; the constructor then checks sizes against the model.
#include <Eigen/Core>
#include <string>

#include "nlobs/common/invalid_input.hpp"

namespace nlobs::detail {

// The options after their validate(): for a constructor's initialiser list, so that a member
// holds validated options and the constructor's body can rely on them.
template <typename Options>
Options validated(Options options) {
  options.validate();
  return options;
}

// Throws InvalidInput("<who>::<field> must <condition> (got <value>)").
[[noreturn]] void invalid_option(const char* who, const char* field, const std::string& condition,
                                 const std::string& got);

// A value as these messages print it: the shortest text that reads back as the same double.
std::string option_value(double value);

void require_name(const char* who, const std::string& name);  // not empty
// Given (not empty) and every entry finite.
void require_finite(const char* who, const char* field, const Eigen::MatrixXd& m);
void require_positive(const char* who, const char* field, double value);      // finite, > 0
void require_non_negative(const char* who, const char* field, double value);  // finite, >= 0
void require_at_least(const char* who, const char* field, double value, double lower);  // finite
void require_at_least(const char* who, const char* field, long value, long lower);

// Sizes against the model, for constructors after validate(): a vector of `size` entries
// ("<who>::<field> must have 3 entries (got 2)"), a matrix of rows × cols ("… must be 2x1 (got
// 1x2)"). Finiteness is validate()'s.
void require_size(const char* who, const char* field, const Eigen::VectorXd& v, Eigen::Index size);
void require_shape(const char* who, const char* field, const Eigen::MatrixXd& m, Eigen::Index rows,
                   Eigen::Index cols);

// A covariance option: empty (a default is used), or square, finite, symmetric and positive
// semi-definite (kSemiDefinite: the Kalman filters) or positive definite (kDefinite: the MHE
// weights by its inverse). "… must be positive definite (got 2x2, not positive definite)".
enum class Definiteness { kSemiDefinite, kDefinite };
void require_covariance(const char* who, const char* field, const Eigen::MatrixXd& m,
                        Definiteness definiteness);
// The given covariance, or `default_scale` · I when empty; then its shape against the model.
Eigen::MatrixXd covariance_or_default(const char* who, const char* field, const Eigen::MatrixXd& m,
                                      Eigen::Index size, double default_scale);

// Q, R and P0 of a Kalman-type observer's options (EkfOptions, UkfOptions, MheOptions), each the
// given matrix or its default — 1e-6 I, 1e-4 I, I — checked against n states and p outputs.
struct Covariances {
  Eigen::MatrixXd process, measurement, initial;
};
template <typename Options>
Covariances covariances_of(const char* who, const Options& o, Eigen::Index n, Eigen::Index p) {
  return {covariance_or_default(who, "process_covariance", o.process_covariance, n, 1e-6),
          covariance_or_default(who, "measurement_covariance", o.measurement_covariance, p, 1e-4),
          covariance_or_default(who, "initial_covariance", o.initial_covariance, n, 1.0)};
}

}  // namespace nlobs::detail
