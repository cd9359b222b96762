// Bad input raises at construction or call with a message naming the option and value.
#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "test_support.hpp"

namespace nlobs {
namespace {

using test::message_of;

#define EXPECT_INVALID(expr, fragment)                                   \
  EXPECT_NE(message_of([&] { expr; }).find(fragment), std::string::npos) \
      << message_of([&] { expr; })

TEST(BadInput, Tolerances) {
  SolverOptions o;
  o.stop.step_tolerance = 0.0;
  EXPECT_INVALID(PicardEngine<1>{o}, "step_tolerance = 0");
  o.stop.step_tolerance = -1e-3;
  EXPECT_INVALID(PicardEngine<1>{o}, "step_tolerance = -0.001");
  o = {};
  o.stop.residual_tolerance = std::numeric_limits<double>::quiet_NaN();
  EXPECT_INVALID(NewtonEngine<1>({}, o), "residual_tolerance = nan");
  o = {};
  o.stop.error_tolerance = 0.0;
  EXPECT_INVALID(PicardEngine<1>{o}, "error_tolerance = 0");
  o = {};
  o.stop.lipschitz_constant = 1.0;
  EXPECT_INVALID(PicardEngine<1>{o}, "lipschitz_constant = 1");
  o = {};
  o.stop.max_iterations = 0;
  EXPECT_INVALID(AitkenEngine<1>{o}, "max_iterations = 0");
  o = {};
  o.stop.max_evaluations = -5;
  EXPECT_INVALID(SteffensenEngine<1>{o}, "max_evaluations = -5");
  o = {};
  o.stop.stagnation_patience = -1;
  EXPECT_INVALID(PicardEngine<1>{o}, "stagnation_patience = -1");
  o = {};
  o.stop.divergence_growth = 1.0;
  EXPECT_INVALID(PicardEngine<1>{o}, "divergence_growth = 1");
  o = {};
  o.stop.step_tolerance.reset();
  o.stop.combine = Combine::kAll;
  EXPECT_INVALID(PicardEngine<1>{o}, "kAll needs at least one");
}

TEST(BadInput, AndersonAndNewtonOptions) {
  EXPECT_INVALID(AndersonEngine<1>({.depth = -1}), "depth = -1");
  EXPECT_INVALID(AndersonEngine<1>({.depth = 17}), "depth = 17");
  EXPECT_NO_THROW(AndersonEngine<Dynamic>({.depth = 40}));
  EXPECT_INVALID(AndersonEngine<1>({.depth = 2, .damping = 0.0}), "damping = 0");
  EXPECT_INVALID(AndersonEngine<1>({.depth = 2, .damping = 1.5}), "damping = 1.5");
  EXPECT_INVALID(AndersonEngine<1>({.depth = 2, .damping = 1.0, .condition_limit = 0.5}),
                 "condition_limit = 0.5");
  EXPECT_INVALID(NewtonEngine<1>({.sufficient_decrease = 0.7}), "sufficient_decrease = 0.7");
  EXPECT_INVALID(NewtonEngine<1>({.backtrack_factor = 1.0}), "backtrack_factor = 1");
  EXPECT_INVALID(NewtonEngine<1>({.max_backtracks = 0}), "max_backtracks = 0");
}

TEST(BadInput, InitialGuess) {
  const auto problem = test::cosine_problem();
  Vector<1> x(std::numeric_limits<double>::infinity());
  EXPECT_INVALID(PicardEngine<1>().solve(problem, x), "x0[0] = inf is not finite");
  x[0] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_INVALID(NewtonEngine<1>().solve(problem, x), "x0[0] = nan");
}

TEST(BadInput, DimensionMismatch) {
  const auto g = [](const Vector<Dynamic>& x, Vector<Dynamic>& out) { out = 0.5 * x; };
  const auto problem = FixedPointProblem<Dynamic>::from_map(g, 3);
  Vector<Dynamic> x = Vector<Dynamic>::Zero(4);
  EXPECT_INVALID(PicardEngine<Dynamic>().solve(problem, x), "size 4");
  EXPECT_INVALID(NewtonEngine<Dynamic>().solve(problem, x), "dimension 3");
  // A user function that returns the wrong size.
  const auto wrong = FixedPointProblem<Dynamic>::from_map(
      [](const Vector<Dynamic>& v) { return Vector<Dynamic>(v.size() + 1); }, 2);
  Vector<Dynamic> y = Vector<Dynamic>::Zero(2);
  EXPECT_INVALID(SteffensenEngine<Dynamic>().solve(wrong, y), "G returned a vector of size 3");
  EXPECT_INVALID(FixedPointProblem<Dynamic>::from_map(g, 0), "n = 0");
  const auto g3 = [](const Vector<3>& v, Vector<3>& out) { out = v; };
  EXPECT_INVALID(FixedPointProblem<3>::from_map(g3, 2), "compile-time size 3");
}

TEST(BadInput, RootAdapter) {
  const auto f = [](const Vector<2>& x, Vector<2>& out) { out = x; };
  const auto root = RootProblem<2>::from_map(f);
  EXPECT_INVALID(to_fixed_point<2>(root, 0.0), "scalar Psi = 0");
  Matrix<Dynamic, Dynamic> psi = Matrix<Dynamic, Dynamic>::Identity(3, 3);
  const auto droot = RootProblem<Dynamic>::from_map(
      [](const Vector<Dynamic>& x, Vector<Dynamic>& out) { out = x; }, 2, 2);
  EXPECT_INVALID(to_fixed_point<Dynamic>(droot, psi), "Psi is 3x3, expected 2x2");
  const auto rect = RootProblem<Dynamic>::from_map(
      [](const Vector<Dynamic>& x, Vector<Dynamic>& out) { out = x.replicate(2, 1); }, 2, 4);
  EXPECT_INVALID(to_fixed_point<Dynamic>(rect), "square system");
}

TEST(BadInput, ContractionBox) {
  const auto problem = test::cosine_problem();
  EXPECT_INVALID(check_contraction<1>(problem, Vector<1>(1.0), Vector<1>(0.0)), "lower <= upper");
  EXPECT_INVALID(check_contraction<1>(problem, Vector<1>(0.0),
                                      Vector<1>(std::numeric_limits<double>::infinity())),
                 "must be finite");
}

}  // namespace
}  // namespace nlobs
