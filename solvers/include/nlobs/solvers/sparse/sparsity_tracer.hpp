#pragma once
// A scalar that carries a value and the set of inputs x_j it depends on, for finding the
// sparsity pattern of a user's F written generic in its scalar type (the code that already runs
// with ceres::Jet for AD): F evaluated once on SparsityTracer inputs x_j ↦ (x_j, {j}) returns in
// F_i the columns of row i of J. The sets are unions along every operation, so an entry is kept
// wherever F_i is computed from x_j, even when ∂F_i/∂x_j happens to vanish at this x (x_j·0):
// the pattern is structural, as the operator-overloading sparsity detectors of ADOL-C and
// SparseConnectivityTracer.jl find it.
//
// Branches: a comparison whose operands depend on x (if (x[0] > 0) …) chooses a path by this x
// alone; the pattern of the other path is not seen. Each such comparison is counted
// (detail::SparsityTracerBranches), and detect_sparsity refuses a pattern found through one.
// min, max, abs, fmin, fmax and copysign are not branches here: their pattern is the union of
// their arguments' whatever the values.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <iterator>
#include <limits>
#include <utility>
#include <vector>

#include "nlobs/solvers/types.hpp"

namespace nlobs {

namespace detail {
// Comparisons of values that depend on x since the counter was last reset, in this thread.
inline thread_local long SparsityTracerBranches = 0;

// Bounds on the work of one trace, for automatic detection (RootProblem::with_autodiff): a
// value that depends on more than `largest_set` inputs, or more than `budget` indices copied in
// all, marks the trace `exceeded`, and from then on values carry no inputs (the trace is cheap
// and its pattern discarded). Unbounded by default (detect_sparsity).
struct SparsityTraceLimits {
  std::size_t largest_set = std::numeric_limits<std::size_t>::max();
  long long budget = std::numeric_limits<long long>::max();
  bool exceeded = false;
};
inline thread_local SparsityTraceLimits SparsityTracerLimits;
}  // namespace detail

// The tracer and its functions live in a namespace of their own: argument-dependent lookup finds
// them from generic code, and they do not hide ::abs, std::exp … from code in namespace nlobs.
namespace sparsity_tracing {

class SparsityTracer {
 public:
  SparsityTracer() = default;
  // A constant: depends on nothing (explicit, as ceres::Jet's, so that generic code written for
  // Jet compiles unchanged).
  explicit SparsityTracer(double value) : value_(value) {}
  // The input x_j.
  SparsityTracer(double value, Index input) : value_(value), inputs_{input} {}

  double value() const { return value_; }
  // The inputs this value depends on: sorted, without repeats.
  const std::vector<Index>& inputs() const { return inputs_; }

  // The result of an operation on a and b: value v, the union of their inputs.
  static SparsityTracer combine(double v, const SparsityTracer& a, const SparsityTracer& b) {
    SparsityTracer r(v);
    if (detail::SparsityTracerLimits.exceeded) return r;
    if (b.inputs_.empty()) {
      r.inputs_ = a.inputs_;
    } else if (a.inputs_.empty()) {
      r.inputs_ = b.inputs_;
    } else {
      r.inputs_.reserve(a.inputs_.size() + b.inputs_.size());
      std::set_union(a.inputs_.begin(), a.inputs_.end(), b.inputs_.begin(), b.inputs_.end(),
                     std::back_inserter(r.inputs_));
    }
    r.count();
    return r;
  }
  // The result of a function of a alone: value v, a's inputs.
  static SparsityTracer follow(double v, const SparsityTracer& a) {
    SparsityTracer r(v);
    if (detail::SparsityTracerLimits.exceeded) return r;
    r.inputs_ = a.inputs_;
    r.count();
    return r;
  }

  SparsityTracer& operator+=(const SparsityTracer& b) { return *this = *this + b; }
  SparsityTracer& operator-=(const SparsityTracer& b) { return *this = *this - b; }
  SparsityTracer& operator*=(const SparsityTracer& b) { return *this = *this * b; }
  SparsityTracer& operator/=(const SparsityTracer& b) { return *this = *this / b; }
  SparsityTracer& operator+=(double b) { return value_ += b, *this; }
  SparsityTracer& operator-=(double b) { return value_ -= b, *this; }
  SparsityTracer& operator*=(double b) { return value_ *= b, *this; }
  SparsityTracer& operator/=(double b) { return value_ /= b, *this; }

  friend SparsityTracer operator+(const SparsityTracer& a) { return a; }
  friend SparsityTracer operator-(const SparsityTracer& a) { return follow(-a.value_, a); }
  friend SparsityTracer operator+(const SparsityTracer& a, const SparsityTracer& b) {
    return combine(a.value_ + b.value_, a, b);
  }
  friend SparsityTracer operator-(const SparsityTracer& a, const SparsityTracer& b) {
    return combine(a.value_ - b.value_, a, b);
  }
  friend SparsityTracer operator*(const SparsityTracer& a, const SparsityTracer& b) {
    return combine(a.value_ * b.value_, a, b);
  }
  friend SparsityTracer operator/(const SparsityTracer& a, const SparsityTracer& b) {
    return combine(a.value_ / b.value_, a, b);
  }
  friend SparsityTracer operator+(const SparsityTracer& a, double b) {
    return follow(a.value_ + b, a);
  }
  friend SparsityTracer operator-(const SparsityTracer& a, double b) {
    return follow(a.value_ - b, a);
  }
  friend SparsityTracer operator*(const SparsityTracer& a, double b) {
    return follow(a.value_ * b, a);
  }
  friend SparsityTracer operator/(const SparsityTracer& a, double b) {
    return follow(a.value_ / b, a);
  }
  friend SparsityTracer operator+(double a, const SparsityTracer& b) {
    return follow(a + b.value_, b);
  }
  friend SparsityTracer operator-(double a, const SparsityTracer& b) {
    return follow(a - b.value_, b);
  }
  friend SparsityTracer operator*(double a, const SparsityTracer& b) {
    return follow(a * b.value_, b);
  }
  friend SparsityTracer operator/(double a, const SparsityTracer& b) {
    return follow(a / b.value_, b);
  }

 private:
  // Charges this value's set to the trace's limits.
  void count() {
    detail::SparsityTraceLimits& limits = detail::SparsityTracerLimits;
    limits.budget -= static_cast<long long>(inputs_.size());
    if (limits.budget < 0 || inputs_.size() > limits.largest_set) {
      limits.exceeded = true;
      inputs_.clear();
    }
  }

  double value_ = 0.0;
  std::vector<Index> inputs_;
};

inline bool depends(const SparsityTracer& a) {
  return !a.inputs().empty();
}

// Comparisons: by value; one whose operands depend on x is a branch (counted).
#define NLOBS_TRACER_COMPARISON(op)                                           \
  inline bool operator op(const SparsityTracer& a, const SparsityTracer& b) { \
    if (depends(a) || depends(b)) ++detail::SparsityTracerBranches;           \
    return a.value() op b.value();                                            \
  }                                                                           \
  inline bool operator op(const SparsityTracer& a, double b) {                \
    if (depends(a)) ++detail::SparsityTracerBranches;                         \
    return a.value() op b;                                                    \
  }                                                                           \
  inline bool operator op(double a, const SparsityTracer& b) {                \
    if (depends(b)) ++detail::SparsityTracerBranches;                         \
    return a op b.value();                                                    \
  }
NLOBS_TRACER_COMPARISON(<)
NLOBS_TRACER_COMPARISON(<=)
NLOBS_TRACER_COMPARISON(>)
NLOBS_TRACER_COMPARISON(>=)
NLOBS_TRACER_COMPARISON(==)
NLOBS_TRACER_COMPARISON(!=)
#undef NLOBS_TRACER_COMPARISON

// Functions of one argument: found by argument-dependent lookup, as ceres::Jet's are, from
// generic code that says `using std::sin; sin(x)`.
#define NLOBS_TRACER_UNARY(name)                            \
  inline SparsityTracer name(const SparsityTracer& a) {     \
    return SparsityTracer::follow(std::name(a.value()), a); \
  }
NLOBS_TRACER_UNARY(abs)
NLOBS_TRACER_UNARY(fabs)
NLOBS_TRACER_UNARY(sqrt)
NLOBS_TRACER_UNARY(cbrt)
NLOBS_TRACER_UNARY(exp)
NLOBS_TRACER_UNARY(exp2)
NLOBS_TRACER_UNARY(expm1)
NLOBS_TRACER_UNARY(log)
NLOBS_TRACER_UNARY(log2)
NLOBS_TRACER_UNARY(log10)
NLOBS_TRACER_UNARY(log1p)
NLOBS_TRACER_UNARY(sin)
NLOBS_TRACER_UNARY(cos)
NLOBS_TRACER_UNARY(tan)
NLOBS_TRACER_UNARY(asin)
NLOBS_TRACER_UNARY(acos)
NLOBS_TRACER_UNARY(atan)
NLOBS_TRACER_UNARY(sinh)
NLOBS_TRACER_UNARY(cosh)
NLOBS_TRACER_UNARY(tanh)
NLOBS_TRACER_UNARY(asinh)
NLOBS_TRACER_UNARY(acosh)
NLOBS_TRACER_UNARY(atanh)
NLOBS_TRACER_UNARY(erf)
NLOBS_TRACER_UNARY(erfc)
#undef NLOBS_TRACER_UNARY
inline SparsityTracer abs2(const SparsityTracer& a) {
  return SparsityTracer::follow(a.value() * a.value(), a);
}
// Piecewise constant: ∂/∂x = 0 almost everywhere, no entry of J.
inline SparsityTracer floor(const SparsityTracer& a) {
  return SparsityTracer(std::floor(a.value()));
}
inline SparsityTracer ceil(const SparsityTracer& a) {
  return SparsityTracer(std::ceil(a.value()));
}
inline bool isfinite(const SparsityTracer& a) {
  return std::isfinite(a.value());
}
inline bool isnan(const SparsityTracer& a) {
  return std::isnan(a.value());
}
inline bool isinf(const SparsityTracer& a) {
  return std::isinf(a.value());
}

// Functions of two arguments, each mix of tracer and double.
#define NLOBS_TRACER_BINARY(name, expr)                                          \
  inline SparsityTracer name(const SparsityTracer& a, const SparsityTracer& b) { \
    const double x = a.value(), y = b.value();                                   \
    return SparsityTracer::combine(expr, a, b);                                  \
  }                                                                              \
  inline SparsityTracer name(const SparsityTracer& a, double y) {                \
    const double x = a.value();                                                  \
    return SparsityTracer::follow(expr, a);                                      \
  }                                                                              \
  inline SparsityTracer name(double x, const SparsityTracer& b) {                \
    const double y = b.value();                                                  \
    return SparsityTracer::follow(expr, b);                                      \
  }
NLOBS_TRACER_BINARY(pow, std::pow(x, y))
NLOBS_TRACER_BINARY(atan2, std::atan2(x, y))
NLOBS_TRACER_BINARY(hypot, std::hypot(x, y))
NLOBS_TRACER_BINARY(fmin, std::fmin(x, y))
NLOBS_TRACER_BINARY(fmax, std::fmax(x, y))
NLOBS_TRACER_BINARY(min, std::min(x, y))
NLOBS_TRACER_BINARY(max, std::max(x, y))
NLOBS_TRACER_BINARY(copysign, std::copysign(x, y))
#undef NLOBS_TRACER_BINARY

}  // namespace sparsity_tracing

using sparsity_tracing::SparsityTracer;

}  // namespace nlobs

// Eigen: matrices of SparsityTracer, and SparsityTracer mixed with double in expressions, as
// ceres/jet.h declares them for Jet.
namespace Eigen {
template <>
struct NumTraits<nlobs::SparsityTracer> {
  using Real = nlobs::SparsityTracer;
  using NonInteger = nlobs::SparsityTracer;
  using Nested = nlobs::SparsityTracer;
  using Literal = nlobs::SparsityTracer;
  static Real dummy_precision() { return Real(1e-12); }
  static Real epsilon() { return Real(std::numeric_limits<double>::epsilon()); }
  static Real highest() { return Real(std::numeric_limits<double>::max()); }
  static Real lowest() { return Real(-std::numeric_limits<double>::max()); }
  static int digits10() { return NumTraits<double>::digits10(); }
  enum {
    IsComplex = 0,
    IsInteger = 0,
    IsSigned = 1,
    ReadCost = 1,
    AddCost = 4,
    MulCost = 4,
    HasFloatingPoint = 1,
    RequireInitialization = 1
  };
  template <bool Vectorized>
  struct Div {
    enum { AVX = false, Cost = 4 };
  };
};
template <typename BinaryOp>
struct ScalarBinaryOpTraits<nlobs::SparsityTracer, double, BinaryOp> {
  using ReturnType = nlobs::SparsityTracer;
};
template <typename BinaryOp>
struct ScalarBinaryOpTraits<double, nlobs::SparsityTracer, BinaryOp> {
  using ReturnType = nlobs::SparsityTracer;
};
}  // namespace Eigen
