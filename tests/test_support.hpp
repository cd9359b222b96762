#pragma once
// Small problems with known answers, shared by the solver tests.
#include <cmath>
#include <limits>
#include <string>

#include "nlobs/solvers/solvers.hpp"

namespace nlobs::test {

// cos x = x: the Dottie number.
inline constexpr double kDottie = 0.739085133215160641655312087673873404;

inline FixedPointProblem<1> cosine_problem() {
  return FixedPointProblem<1>::with_autodiff([](const auto& x) {
    using std::cos;
    using T = typename std::decay_t<decltype(x)>::Scalar;
    Eigen::Matrix<T, 1, 1> g;
    g[0] = cos(x[0]);
    return g;
  });
}

// Linear contraction G(x) = A x + b with A diagonal: Aitken and Steffensen are exact on it.
inline FixedPointProblem<3> diagonal_linear_problem(const Eigen::Vector3d& rates,
                                                    const Eigen::Vector3d& b) {
  return FixedPointProblem<3>::with_jacobian(
      [rates, b](const Vector<3>& x, Vector<3>& g) { g = rates.cwiseProduct(x) + b; },
      [rates](const Vector<3>& /*x*/, Matrix<3, 3>& j) { j = rates.asDiagonal(); });
}

// The message of the InvalidInput that f throws, or "<no exception>".
template <typename F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const InvalidInput& e) {
    return e.what();
  }
  return "<no exception>";
}

inline SolverOptions tolerance(double step) {
  SolverOptions o;
  o.stop.step_tolerance = step;
  return o;
}

}  // namespace nlobs::test
