// Sparse Jacobians from few evaluations: the pattern found by evaluating a generic F once on
// SparsityTracer inputs, a column colouring of it, and the compressed Jacobian by AD and by
// differences against the dense AD Jacobian. Problems nlobs does not ship: Broyden's tridiagonal
// function, the 2-D Bratu residual (PETSc's SNES ex5), a random sparse nonlinear map.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "large_test_problems.hpp"
#include "nlobs/solvers/autodiff.hpp"
#include "nlobs/solvers/sparse/compressed_jacobian.hpp"
#include "nlobs/solvers/sparse/pattern_bandwidths.hpp"
#include "nlobs/solvers/sparse/sparse_jacobian.hpp"
#include "test_support.hpp"

namespace nlobs {
namespace {

using test::bratu;
using test::broyden_tridiagonal;

std::vector<std::pair<Index, Index>> five_point_entries(Index s) {
  std::vector<std::pair<Index, Index>> e;
  for (Index r = 0; r < s; ++r) {
    for (Index c = 0; c < s; ++c) {
      const Index p = r * s + c;
      e.emplace_back(p, p);
      if (r > 0) e.emplace_back(p, p - s);
      if (r + 1 < s) e.emplace_back(p, p + s);
      if (c > 0) e.emplace_back(p, p - 1);
      if (c + 1 < s) e.emplace_back(p, p + 1);
    }
  }
  return e;
}

// A random sparse nonlinear map Rⁿ → Rᵐ: row i multiplies sin and exp of its own random
// columns (its pattern, also returned).
struct RandomMap {
  std::vector<std::vector<Index>> cols;
  template <typename V>
  auto operator()(const V& x) const {
    using T = typename V::Scalar;
    using std::exp;
    using std::sin;
    Vector<Dynamic, T> f(static_cast<Index>(cols.size()));
    for (std::size_t i = 0; i < cols.size(); ++i) {
      T acc(0.1 * static_cast<double>(i));
      for (const Index j : cols[i])
        acc += sin(x[j]) * exp(0.1 * x[j]) + x[j] * x[(j + 1) % x.size()];
      f[static_cast<Index>(i)] = acc;
    }
    return f;
  }
};
RandomMap random_map(Index m, Index n, int per_row, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<Index> pick(0, n - 1);
  RandomMap map;
  map.cols.resize(static_cast<std::size_t>(m));
  for (auto& row : map.cols) {
    for (int k = 0; k < per_row; ++k) row.push_back(pick(rng));
  }
  return map;
}

Eigen::MatrixXd dense_autodiff(auto f, const Eigen::VectorXd& x, Index m) {
  Eigen::MatrixXd jac(m, x.size());
  autodiff_jacobian<Dynamic, Dynamic>(f, x, jac);
  return jac;
}

TEST(SparsityDetection, FindsTheBandOfBroydensTridiagonalFunction) {
  auto f = broyden_tridiagonal();
  const Eigen::VectorXd x = Eigen::VectorXd::Constant(50, -1.0);
  const SparsityPattern p = detect_sparsity(f, x);
  EXPECT_EQ(p, SparsityPattern::band(50, 1, 1));
  EXPECT_EQ(p.nonzeros(), 3 * 50 - 2);
}

TEST(SparsityDetection, FindsTheFivePointStencilOfBratu) {
  const Index s = 12;
  auto f = bratu(s);
  const Eigen::VectorXd u = Eigen::VectorXd::Zero(s * s);
  EXPECT_EQ(detect_sparsity(f, u, s * s),
            SparsityPattern::from_entries(s * s, s * s, five_point_entries(s)));
}

TEST(SparsityDetection, TheStructureNotTheValues) {
  // An entry whose derivative vanishes at this x (x_1 · 0, x_2 − x_2, e^{x_3} at NaN) is
  // still an entry: the pattern is what F is computed from.
  auto f = [](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    using std::exp;
    Vector<Dynamic, T> out(3);
    out[0] = x[0] + x[1] * 0.0;
    out[1] = x[2] - x[2];
    out[2] = exp(x[3]) + T(1.0);
    return out;
  };
  Eigen::VectorXd x(4);
  x << 1.0, 2.0, 3.0, std::numeric_limits<double>::quiet_NaN();
  const SparsityPattern p = detect_sparsity(f, x);
  EXPECT_EQ(p, SparsityPattern::from_entries(3, 4, {{0, 0}, {0, 1}, {1, 2}, {2, 3}}));
}

TEST(SparsityDetection, EigenExpressionsAndFunctionsOfTwoArguments) {
  // A user's F written with Eigen operations and a constant double matrix.
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(3, 4);
  a(0, 1) = 2.0;
  a(2, 0) = -1.0;
  a(2, 3) = 0.5;
  auto f = [a](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    using std::atan2;
    using std::pow;
    Vector<Dynamic, T> out = a.cast<T>() * x;  // a dense product: every column, structurally
    out[1] = pow(x[1], 2.0) + atan2(x[2], T(1.0)) * x.head(1).squaredNorm();
    return out;
  };
  const SparsityPattern p = detect_sparsity(f, Eigen::VectorXd::Ones(4));
  EXPECT_EQ(p.row_start[1] - p.row_start[0], 4);  // the product reads every column
  EXPECT_EQ(p.row_start[2] - p.row_start[1], 3);  // x1, x2 and x0
  EXPECT_TRUE(p.contains(1, 0) && p.contains(1, 1) && p.contains(1, 2) && !p.contains(1, 3));
}

TEST(SparsityDetection, ABranchOnXIsRefusedAndMinMaxAbsAreNot) {
  // The pattern of an if on x depends on x: one evaluation sees one branch. Refused, named.
  auto branchy = [](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    Vector<Dynamic, T> out(2);
    out[0] = x[0] > 0.0 ? x[0] * x[1] : x[0];
    out[1] = x[1];
    return out;
  };
  const std::string message =
      test::message_of([&] { detect_sparsity(branchy, Eigen::VectorXd::Ones(2)); });
  EXPECT_NE(message.find("compared a value that depends on x (1 comparisons)"), std::string::npos)
      << message;
  // A comparison of constants is no branch; max, abs and fmin take the union of their arguments.
  auto unions = [](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    using std::abs;
    using std::fmin;
    using std::max;
    Vector<Dynamic, T> out(2);
    out[0] = T(1.0) < T(2.0) ? max(x[0], x[1]) : x[2];
    out[1] = abs(x[2]) + fmin(x[3], 0.0);
    return out;
  };
  const SparsityPattern p = detect_sparsity(unions, Eigen::VectorXd::Ones(4));
  EXPECT_EQ(p, SparsityPattern::from_entries(2, 4, {{0, 0}, {0, 1}, {1, 2}, {1, 3}}));
  // The refusal leaves nothing behind: the next detection starts clean.
  EXPECT_NO_THROW(detect_sparsity(unions, Eigen::VectorXd::Ones(4)));
}

// The band holding a pattern (what auto's band-LU choice and KINSOL's band are sized by): a band
// declared with its widths, an arrow whose first column and last row widen it to n − 1, an empty
// row, and the 5-point stencil, whose widths are the grid's side.
TEST(SparsityPattern, BandwidthsAreThoseOfTheBandHoldingIt) {
  const PatternBandwidths band = pattern_bandwidths(SparsityPattern::band(10, 2, 3));
  EXPECT_EQ(band.lower, 2);
  EXPECT_EQ(band.upper, 3);
  const PatternBandwidths arrow =
      pattern_bandwidths(SparsityPattern::from_entries(5, 5, {{0, 0}, {4, 0}, {1, 4}, {2, 2}}));
  EXPECT_EQ(arrow.lower, 4);
  EXPECT_EQ(arrow.upper, 3);
  const PatternBandwidths empty = pattern_bandwidths(SparsityPattern::from_entries(3, 3, {}));
  EXPECT_EQ(empty.lower, 0);
  EXPECT_EQ(empty.upper, 0);
  const Index s = 7;
  auto f = test::bratu(s);
  const PatternBandwidths stencil =
      pattern_bandwidths(detect_sparsity(f, Vector<Dynamic>::Zero(s * s), s * s));
  EXPECT_EQ(stencil.lower, s);
  EXPECT_EQ(stencil.upper, s);
}

TEST(ColumnColouring, IsValidAndAsSmallAsTheLongestRowOnStructuredPatterns) {
  const ColumnColouring tri = colour_columns(SparsityPattern::band(1000, 1, 1));
  EXPECT_EQ(tri.colours, 3);
  const SparsityPattern band = SparsityPattern::band(200, 2, 5);
  EXPECT_EQ(colour_columns(band).colours, 8);
  const Index s = 30;
  const SparsityPattern stencil =
      SparsityPattern::from_entries(s * s, s * s, five_point_entries(s));
  const ColumnColouring five = colour_columns(stencil);
  EXPECT_TRUE(valid_colouring(stencil, five));
  EXPECT_EQ(five.colours, 5);
  // A diagonal needs one colour, as does an empty pattern (nothing to tell apart); a full row
  // all n.
  EXPECT_EQ(colour_columns(SparsityPattern::band(10, 0, 0)).colours, 1);
  EXPECT_EQ(colour_columns(SparsityPattern::from_entries(3, 4, {})).colours, 1);
  std::vector<std::pair<Index, Index>> row;
  for (Index j = 0; j < 7; ++j) row.emplace_back(2, j);
  EXPECT_EQ(colour_columns(SparsityPattern::from_entries(5, 7, row)).colours, 7);
}

TEST(ColumnColouring, NoTwoColumnsOfOneColourShareARowOnRandomPatterns) {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const RandomMap map = random_map(60, 80, 1 + static_cast<int>(seed % 6), seed);
    std::vector<std::pair<Index, Index>> entries;
    for (std::size_t i = 0; i < map.cols.size(); ++i) {
      for (const Index j : map.cols[i]) entries.emplace_back(static_cast<Index>(i), j);
    }
    const SparsityPattern p = SparsityPattern::from_entries(60, 80, entries);
    ColumnColouring c = colour_columns(p);
    ASSERT_TRUE(valid_colouring(p, c)) << seed;
    Index longest = 0;
    for (Index i = 0; i < p.rows; ++i)
      longest = std::max(longest, p.row_start[i + 1] - p.row_start[i]);
    EXPECT_GE(c.colours, longest) << seed;
    // The check can fail: merge two colours that share a row.
    if (c.colours >= 2 && longest >= 2) {
      for (int& k : c.colour) k = k == 1 ? 0 : k;
      EXPECT_FALSE(valid_colouring(p, c)) << seed;
    }
  }
}

TEST(CompressedJacobian, AutodiffEqualsTheDenseAutodiffJacobian) {
  {
    auto f = broyden_tridiagonal();
    Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(300, -2.0, 1.5);
    CompressedJacobian cj(detect_sparsity(f, x));
    EXPECT_EQ(cj.autodiff_passes(), 1);  // 3 colours in one pass; dense AD takes ⌈300/8⌉ = 38
    SparseJacobian jac;
    cj.autodiff(f, x, jac);
    EXPECT_EQ(Eigen::MatrixXd(jac), dense_autodiff(f, x, 300));
    x.array() += 0.25;  // again, at another point: the structure is kept, the values replaced
    cj.autodiff(f, x, jac);
    EXPECT_EQ(Eigen::MatrixXd(jac), dense_autodiff(f, x, 300));
  }
  {
    const Index s = 9;
    auto f = bratu(s);
    const Eigen::VectorXd u = Eigen::VectorXd::LinSpaced(s * s, 0.0, 1.0);
    CompressedJacobian cj(detect_sparsity(f, u, s * s));
    EXPECT_EQ(cj.colouring().colours, 5);
    SparseJacobian jac;
    cj.autodiff(f, u, jac);
    EXPECT_EQ(Eigen::MatrixXd(jac), dense_autodiff(f, u, s * s));
  }
  for (unsigned seed = 1; seed <= 5; ++seed) {  // more than 8 colours: several passes
    const RandomMap map = random_map(40, 30, 6, seed);
    const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(30, -1.0, 2.0);
    CompressedJacobian cj(detect_sparsity(map, x));
    EXPECT_GT(cj.autodiff_passes(), 1) << seed;
    SparseJacobian jac;
    cj.autodiff(map, x, jac);
    EXPECT_LE((Eigen::MatrixXd(jac) - dense_autodiff(map, x, 40)).cwiseAbs().maxCoeff(), 0.0)
        << seed;
  }
}

TEST(CompressedJacobian, DifferencesMatchTheAutodiffJacobianInColoursEvaluations) {
  const Index s = 10;
  auto f = bratu(s);
  const Eigen::VectorXd u = Eigen::VectorXd::LinSpaced(s * s, 0.0, 2.0);
  CompressedJacobian cj(detect_sparsity(f, u, s * s));
  int calls = 0;
  auto on_doubles = [&](const Eigen::VectorXd& x, Eigen::VectorXd& out) {
    ++calls;
    f(x, out);
  };
  Eigen::VectorXd f0;
  on_doubles(u, f0);
  calls = 0;
  SparseJacobian jac;
  EXPECT_EQ(cj.differences(on_doubles, u, f0, jac), 5);
  EXPECT_EQ(calls, 5);  // instead of n = 100
  const Eigen::MatrixXd exact = dense_autodiff(f, u, s * s);
  // Forward differences: error ~ √ε · |F''| h-scaled; entries are ~ 4/h² = 484.
  EXPECT_LE((Eigen::MatrixXd(jac) - exact).cwiseAbs().maxCoeff(),
            1e-5 * exact.cwiseAbs().maxCoeff());
  EXPECT_TRUE(u.isApprox(Eigen::VectorXd::LinSpaced(s * s, 0.0, 2.0)));  // x untouched
}

TEST(CompressedJacobian, ADeclaredPatternThatMissesAnEntryIsFound) {
  // A pentadiagonal F declared tridiagonal: the compressed Jacobian is then silently wrong (the
  // missing entry lands in its row's entry of the same colour); missing_entry names it.
  auto f = [](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    const Index n = x.size();
    Vector<Dynamic, T> out(n);
    for (Index i = 0; i < n; ++i) {
      out[i] = x[i] * x[i];
      if (i > 0) out[i] += x[i - 1];
      if (i + 1 < n) out[i] += x[i + 1];
      if (i == 4) out[i] += 3.0 * x[7];
    }
    return out;
  };
  const Eigen::VectorXd x = Eigen::VectorXd::Ones(10);
  const SparsityPattern declared = SparsityPattern::band(10, 1, 1);
  CompressedJacobian wrong(declared);
  SparseJacobian jac;
  wrong.autodiff(f, x, jac);
  EXPECT_NE(Eigen::MatrixXd(jac), dense_autodiff(f, x, 10));
  const auto missing = missing_entry(f, x, declared);
  ASSERT_TRUE(missing.has_value());
  EXPECT_EQ(*missing, std::make_pair(Index{4}, Index{7}));
  EXPECT_FALSE(missing_entry(f, x, detect_sparsity(f, x)).has_value());
}

TEST(CompressedJacobian, BadInputIsNamed) {
  EXPECT_NE(test::message_of([] {
              SparsityPattern::band(10, 10, 1);
            }).find("lower bandwidth 10 is out of range"),
            std::string::npos);
  EXPECT_NE(test::message_of([] {
              SparsityPattern::band(10, 1, -1);
            }).find("upper bandwidth -1 is out of range"),
            std::string::npos);
  EXPECT_NE(test::message_of([] {
              SparsityPattern::from_entries(3, 3, {{1, 3}});
            }).find("entry (1, 3) lies outside the 3x3 matrix"),
            std::string::npos);
  auto f = broyden_tridiagonal();
  CompressedJacobian cj(SparsityPattern::band(5, 1, 1));
  SparseJacobian jac;
  EXPECT_NE(test::message_of([&] {
              cj.autodiff(f, Eigen::VectorXd::Ones(6), jac);
            }).find("x has 6 components, the pattern 5 columns"),
            std::string::npos);
  auto short_f = [](const Eigen::VectorXd& x, Eigen::VectorXd& out) { out = x.head(4); };
  EXPECT_NE(test::message_of([&] {
              cj.differences(short_f, Eigen::VectorXd::Ones(5), Eigen::VectorXd::Ones(5), jac);
            }).find("F returned 4 values, the pattern has 5 rows"),
            std::string::npos);
}

}  // namespace
}  // namespace nlobs
