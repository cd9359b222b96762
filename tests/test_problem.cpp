// Problems, Jacobian sources, the root → fixed-point adapter and the contraction check.
#include <gtest/gtest.h>

#include "test_support.hpp"

namespace nlobs {
namespace {

// F: R² → R³ (m ≠ n), generic in the scalar.
struct Curve {
  template <typename T>
  void operator()(const Eigen::Matrix<T, 2, 1>& x, Eigen::Matrix<T, 3, 1>& f) const {
    using std::sin;
    f << x[0] * x[1], sin(x[0]) + x[1], x[1] * x[1] - 2.0 * x[0];
  }
};

TEST(Problem, RootProblemNonSquareAutodiffJacobian) {
  const auto root = RootProblem<2, 3>::with_autodiff(Curve{});
  EXPECT_EQ(root.size(), 2);
  EXPECT_EQ(root.residual_size(), 3);
  const Vector<2> x(0.3, -1.2);
  Matrix<3, 2> j;
  root.jacobian(x, j);
  Matrix<3, 2> expected;
  expected << x[1], x[0], std::cos(x[0]), 1.0, -2.0, 2.0 * x[1];
  EXPECT_LT((j - expected).cwiseAbs().maxCoeff(), 1e-15);

  // Dynamic sizes go through Eigen's AutoDiffScalar.
  const auto droot = RootProblem<Dynamic, Dynamic>::with_autodiff(
      [](const auto& v) {
        using std::sin;
        using T = typename std::decay_t<decltype(v)>::Scalar;
        Eigen::Matrix<T, Eigen::Dynamic, 1> f(3);
        f << v[0] * v[1], sin(v[0]) + v[1], v[1] * v[1] - 2.0 * v[0];
        return f;
      },
      2, 3);
  Matrix<Dynamic, Dynamic> dj;
  droot.jacobian(Vector<Dynamic>(x), dj);
  EXPECT_LT((dj - expected).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(Problem, AdapterScalingsGiveTheSameRoot) {
  // F(x) = [x1 − cos x2, x2 − 0.5 sin x1] (∂F ≈ I: Ψ = −I turns x + ΨF into a contraction).
  const auto root = RootProblem<2>::with_autodiff([](const auto& x) {
    using std::cos;
    using std::sin;
    using T = typename std::decay_t<decltype(x)>::Scalar;
    Eigen::Matrix<T, 2, 1> f;
    f << x[0] - cos(x[1]), x[1] - 0.5 * sin(x[0]);
    return f;
  });
  const SolverOptions o = test::tolerance(1e-13);
  Vector<2> a = Vector<2>::Zero(), b = Vector<2>::Zero(), c = Vector<2>::Zero();
  EXPECT_TRUE(PicardEngine<2>(o).solve(to_fixed_point<2>(root, -1.0), a).converged());
  EXPECT_TRUE(PicardEngine<2>(o).solve(to_fixed_point<2>(root, -0.8), b).converged());
  const Matrix<2, 2> psi = -Matrix<2, 2>::Identity();
  EXPECT_TRUE(PicardEngine<2>(o).solve(to_fixed_point<2>(root, psi), c).converged());
  Vector<2> fa;
  root.evaluate(a, fa);
  EXPECT_LT(fa.lpNorm<Eigen::Infinity>(), 1e-12);
  EXPECT_LT((a - b).lpNorm<Eigen::Infinity>(), 1e-12);
  EXPECT_LT((a - c).lpNorm<Eigen::Infinity>(), 1e-12);

  // ∂G = I + Ψ ∂F.
  const auto g = to_fixed_point<2>(root, psi);
  Matrix<2, 2> dg, df;
  g.jacobian(a, dg);
  root.jacobian(a, df);
  EXPECT_LT((dg - (Matrix<2, 2>::Identity() - df)).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_EQ(g.jacobian_source(), JacobianSource::kAutoDiff);
}

TEST(Problem, IdentityAdapterIsFPlusX) {
  const auto root = RootProblem<2>::from_map(
      [](const Vector<2>& x, Vector<2>& f) { f = Vector<2>(x[0] * x[1], x[0] - 1.0); });
  const auto g = to_fixed_point(root);
  Vector<2> out;
  g.evaluate(Vector<2>(2.0, 3.0), out);
  EXPECT_EQ(out, Vector<2>(8.0, 4.0));
  EXPECT_FALSE(g.has_jacobian());
  EXPECT_EQ(g.jacobian_source(), JacobianSource::kFiniteDifference);
}

TEST(Problem, FiniteDifferenceMatchesAutodiff) {
  const auto ad = test::cosine_problem();
  Vector<1> x(0.4), gx;
  ad.evaluate(x, gx);
  Matrix<1, 1> exact, fwd, ctr;
  ad.jacobian(x, exact);
  FiniteDifferenceWorkspace<1> w;
  EXPECT_EQ(finite_difference_jacobian(ad, x, gx, fwd, FiniteDifference::kForward, w), 1);
  EXPECT_EQ(finite_difference_jacobian(ad, x, gx, ctr, FiniteDifference::kCentral, w), 2);
  EXPECT_NEAR(fwd(0, 0), exact(0, 0), 1e-7);
  EXPECT_NEAR(ctr(0, 0), exact(0, 0), 1e-10);
}

TEST(Contraction, LinearMapKnownNorm) {
  Matrix<2, 2> a;
  a << 0.5, -0.3, 0.2, 0.6;  // ‖A‖∞ = 0.8, largest entry 0.6
  const auto contraction =
      FixedPointProblem<2>::from_map([a](const Vector<2>& x, Vector<2>& g) { g = a * x; });
  const auto r = check_contraction<2>(contraction, Vector<2>(-1, -1), Vector<2>(1, 1));
  EXPECT_NEAR(r.max_jacobian_norm, 0.8, 1e-9);
  EXPECT_NEAR(r.max_entry, 0.6, 1e-9);
  EXPECT_EQ(r.max_entry_row, 1);
  EXPECT_EQ(r.max_entry_col, 1);
  EXPECT_TRUE(r.is_contraction());
  EXPECT_TRUE(r.entrywise_condition());

  // Every entry below 1, yet ‖∂G‖∞ = 1.2: the paper's entry-wise test passes, the norm fails.
  Matrix<2, 2> b;
  b << 0.6, 0.6, 0.1, 0.1;
  const auto not_contraction =
      FixedPointProblem<2>::with_jacobian([b](const Vector<2>& x, Vector<2>& g) { g = b * x; },
                                          [b](const Vector<2>&, Matrix<2, 2>& j) { j = b; });
  const auto s = check_contraction<2>(not_contraction, Vector<2>(-1, -1), Vector<2>(1, 1));
  EXPECT_TRUE(s.entrywise_condition());
  EXPECT_FALSE(s.is_contraction());
  EXPECT_NEAR(s.max_jacobian_norm, 1.2, 1e-12);
}

TEST(Contraction, NonlinearMaximumFoundBySampling) {
  // G(x) = 0.9 sin(x): |G'| = 0.9|cos x| peaks at x = 0, inside the box, not at a corner.
  const auto g = FixedPointProblem<1>::with_autodiff([](const auto& x) {
    using std::sin;
    using T = typename std::decay_t<decltype(x)>::Scalar;
    Eigen::Matrix<T, 1, 1> out;
    out[0] = 0.9 * sin(x[0]);
    return out;
  });
  const auto r = check_contraction<1>(g, Vector<1>(-2.0), Vector<1>(2.5));
  EXPECT_NEAR(r.max_jacobian_norm, 0.9, 1e-4);  // found among 2000 samples
  EXPECT_TRUE(r.is_contraction());
  EXPECT_EQ(r.points, 1 + 2 + 2000);
}

}  // namespace
}  // namespace nlobs
