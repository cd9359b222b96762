#pragma once
// A scalar objective f: Rⁿ → R for minimisation engines (NLopt), with its gradient from the
// user, from forward-mode AD (ceres::Jet for fixed sizes, Eigen AutoDiffScalar for dynamic
// ones), or left to finite differences.
#include <functional>
#include <sstream>

#include "nlobs/solvers/autodiff.hpp"
#include "nlobs/solvers/problem.hpp"

namespace nlobs {

template <int N = Dynamic>
class ObjectiveProblem {
 public:
  using VectorType = Vector<N>;
  using Function = std::function<double(const VectorType&)>;
  using Gradient = std::function<void(const VectorType&, VectorType&)>;

  template <typename F>
  static ObjectiveProblem from_function(F f, Index n = N) {
    return ObjectiveProblem(n, Function(std::move(f)), {}, JacobianSource::kFiniteDifference);
  }
  // f generic in its scalar type (returns T for a vector of T).
  template <typename F>
  static ObjectiveProblem with_autodiff(F f, Index n = N) {
    Gradient g = [f, n](const VectorType& x, VectorType& grad) mutable {
      Matrix<1, N> row(1, n);
      auto as_vector = [&f](const auto& v) {
        using T = typename std::decay_t<decltype(v)>::Scalar;
        Eigen::Matrix<T, 1, 1> out;
        out[0] = f(v);
        return out;
      };
      autodiff_jacobian<N, 1>(as_vector, x, row);
      grad = row.transpose();
    };
    Function value = [f](const VectorType& x) mutable { return static_cast<double>(f(x)); };
    return ObjectiveProblem(n, std::move(value), std::move(g), JacobianSource::kAutoDiff);
  }
  template <typename F, typename G>
  static ObjectiveProblem with_gradient(F f, G g, Index n = N) {
    return ObjectiveProblem(n, Function(std::move(f)), Gradient(std::move(g)),
                            JacobianSource::kUserSupplied);
  }

  Index size() const { return n_; }
  bool has_gradient() const { return static_cast<bool>(gradient_); }
  JacobianSource gradient_source() const { return source_; }
  double evaluate(const VectorType& x) const { return f_(x); }
  void gradient(const VectorType& x, VectorType& g) const { gradient_(x, g); }

 private:
  ObjectiveProblem(Index n, Function f, Gradient g, JacobianSource source)
      : n_(n), f_(std::move(f)), gradient_(std::move(g)), source_(source) {
    if (n_ < 1 || (N != Dynamic && n_ != N)) {
      std::ostringstream os;
      os << "ObjectiveProblem: dimension n = " << n_ << " is invalid";
      throw InvalidInput(os.str());
    }
  }
  Index n_;
  Function f_;
  Gradient gradient_;
  JacobianSource source_;
};

}  // namespace nlobs
