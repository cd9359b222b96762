#pragma once
// Small problems with known answers, shared by the solver tests.
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "invalid_argument_message.hpp"
#include "nlobs/models/model.hpp"
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

// Every engine spec that solves with a Jacobian (each globalisation of newton apart), in the
// order of the documentation: the tests that every such engine must pass loop over it.
inline const std::array<std::string, 8> kJacobianEngineSpecs = {
    "newton",  "newton:linesearch=1", "newton:trustregion=1", "dogleg",
    "broyden", "levenberg-marquardt", "pseudo-transient",     "auto"};

inline SolverOptions tolerance(double step) {
  SolverOptions o;
  o.stop.step_tolerance = step;
  return o;
}

// The Newton-type engines' tests: steps to 1e-13, |F|∞ to 1e-12.
inline SolverOptions strict() {
  SolverOptions o = tolerance(1e-13);
  o.stop.residual_tolerance = 1e-12;
  return o;
}

// F(x) = [x1² + x2² − 4, x1 − x2]: root (√2, √2).
inline RootProblem<2> circle_line() {
  return RootProblem<2>::with_autodiff([](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    Eigen::Matrix<T, 2, 1> f;
    f << x[0] * x[0] + x[1] * x[1] - 4.0, x[0] - x[1];
    return f;
  });
}

// x⁺ = scale · x², y = x: a model that overflows (scale 1e200: at the first step from |x| > 1).
struct Squaring : ModelSizes<1, 0, 1> {
  double scale = 1e200;
  template <typename T>
  State<T> f(const State<T>& x, const Input&, long) const {
    return State<T>(x[0] * x[0] * scale);
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return Output<T>(x[0]);
  }
};

}  // namespace nlobs::test
