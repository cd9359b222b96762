// ProjectedGaussNewton (least_squares/projected_gauss_newton.hpp) on a problem nlobs does not
// ship: fitting y = a e^{−b t} with a box on (a, b). Its success (free and at a bound), each stop
// rule (converged, max_iterations, stagnated, singular_jacobian, non_finite) and its options'
// validation. The MHE is its other user (test_mhe.cpp).
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "nlobs/common/invalid_input.hpp"
#include "nlobs/solvers/least_squares/projected_gauss_newton.hpp"

namespace nlobs {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// r_i = a e^{−b t_i} − y_i, V = ‖r‖², z = (a, b) in [lower, upper]; H = JᵀJ, g = Jᵀr.
struct ExponentialFit {
  Eigen::VectorXd t, y;
  Eigen::Vector2d z, trial, d, g, lower{-kInf, -kInf}, upper{kInf, kInf};
  Eigen::Matrix2d h;
  bool flip_gradient = false;  // a hostile linearisation: g of the wrong sign

  double value(const Eigen::Vector2d& p) const {
    const double v = ((p[0] * (-p[1] * t.array()).exp()) - y.array()).matrix().squaredNorm();
    return std::isfinite(v) ? v : kInf;
  }
  double start_cost() {
    trial = z;
    return value(z);
  }
  double linearise() {
    const Eigen::ArrayXd e = (-z[1] * t.array()).exp();
    Eigen::MatrixXd jac(t.size(), 2);
    jac.col(0) = e.matrix();
    jac.col(1) = (-z[0] * t.array() * e).matrix();
    const Eigen::VectorXd r = (z[0] * e - y.array()).matrix();
    h = jac.transpose() * jac;
    g = jac.transpose() * r;
    if (flip_gradient) g = -g;
    double projected = 0.0;
    for (int c = 0; c < 2; ++c) {
      if ((z[c] <= lower[c] && g[c] > 0.0) || (z[c] >= upper[c] && g[c] < 0.0)) {
        h.row(c).setZero();
        h.col(c).setZero();
        h(c, c) = 1.0;
        g[c] = 0.0;
      } else {
        projected = std::max(projected, std::abs(g[c]));
      }
    }
    return projected;
  }
  bool newton_direction() {
    const Eigen::LLT<Eigen::Matrix2d> llt(h);
    if (llt.info() != Eigen::Success) return false;
    d = -llt.solve(g);
    return d.allFinite();
  }
  void gradient_direction() { d = -g.cwiseQuotient(h.diagonal()); }
  std::pair<double, double> project(double alpha) {
    trial = (z + alpha * d).cwiseMax(lower).cwiseMin(upper);
    const Eigen::Vector2d s = trial - z;
    return {g.dot(s), s.cwiseAbs().maxCoeff()};
  }
  double trial_cost() { return value(trial); }
  void accept() { z = trial; }
  double norm() const { return z.cwiseAbs().maxCoeff(); }
};

static_assert(ProjectedGaussNewtonProblem<ExponentialFit>);

ExponentialFit decay(double a, double b) {
  ExponentialFit fit;
  fit.t = Eigen::VectorXd::LinSpaced(20, 0.0, 4.0);
  fit.y = a * (-b * fit.t.array()).exp();
  return fit;
}

TEST(ProjectedGaussNewton, FitsAnExponentialWithoutBounds) {
  ExponentialFit fit = decay(2.0, 0.5);
  fit.z = Eigen::Vector2d(1.0, 0.1);
  const Summary s = ProjectedGaussNewton().minimise(fit);
  ASSERT_EQ(s.status, Status::kConverged) << s.full_report();
  EXPECT_NEAR(fit.z[0], 2.0, 1e-9);
  EXPECT_NEAR(fit.z[1], 0.5, 1e-9);
  EXPECT_LE(*s.objective, 1e-18);
  EXPECT_EQ(s.engine, std::string(ProjectedGaussNewton::kName));
  EXPECT_EQ(s.iterations, s.jacobian_evaluations);
  // V at the start and at each trial; the last linearisation ended the run without a trial.
  EXPECT_GE(s.function_evaluations, s.iterations);
}

TEST(ProjectedGaussNewton, StopsAtTheBoundThatHoldsTheMinimiser) {
  ExponentialFit fit = decay(2.0, 0.5);
  fit.upper = Eigen::Vector2d(kInf, 0.3);  // b ≤ 0.3, the true 0.5 outside
  fit.z = Eigen::Vector2d(1.0, 0.1);
  const Summary s = ProjectedGaussNewton().minimise(fit);
  ASSERT_EQ(s.status, Status::kConverged) << s.full_report();
  EXPECT_EQ(fit.z[1], 0.3);  // on the bound, not past it
  // First-order optimality on the box: ∂V/∂a = 0, ∂V/∂b < 0 (V falls as b leaves the box).
  // (To the cost test's resolution: −2gᵀd ≤ 1e-12 V with V ≈ 0.5 allows |∂V/∂a| ~ 1e-6.)
  EXPECT_LE(s.residual_norm, 1e-5);
  const Eigen::ArrayXd e = (-0.3 * fit.t.array()).exp();
  const Eigen::ArrayXd r = fit.z[0] * e - fit.y.array();
  EXPECT_NEAR((r * e).sum(), 0.0, 1e-5);
  EXPECT_LT((r * (-fit.z[0] * fit.t.array() * e)).sum(), 0.0);
}

TEST(ProjectedGaussNewton, MaxIterationsStillLowersTheCost) {
  ExponentialFit fit = decay(2.0, 0.5);
  fit.z = Eigen::Vector2d(0.2, 3.0);
  const double start = fit.value(fit.z);
  const Summary s = ProjectedGaussNewton({.max_iterations = 1}).minimise(fit);
  EXPECT_EQ(s.status, Status::kMaxIterations);
  EXPECT_EQ(s.iterations, 1);
  EXPECT_LT(*s.objective, start);
  EXPECT_EQ(*s.objective, fit.value(fit.z));  // the objective is the answer's
}

TEST(ProjectedGaussNewton, AHostileLinearisationStagnatesWithoutMoving) {
  ExponentialFit fit = decay(2.0, 0.5);
  fit.z = Eigen::Vector2d(1.0, 0.1);
  fit.flip_gradient = true;  // every direction it gives climbs V
  const Eigen::Vector2d start = fit.z;
  const Summary s = ProjectedGaussNewton().minimise(fit);
  EXPECT_EQ(s.status, Status::kStagnated) << s.full_report();
  EXPECT_EQ(fit.z, start);
  EXPECT_NE(s.message.find("no decrease"), std::string::npos) << s.message;
}

TEST(ProjectedGaussNewton, ASingularMatrixIsNamed) {
  ExponentialFit fit = decay(2.0, 0.5);
  fit.z = Eigen::Vector2d(0.0, 0.1);  // a = 0: ∂r/∂b = 0, JᵀJ singular
  const Summary s = ProjectedGaussNewton().minimise(fit);
  EXPECT_EQ(s.status, Status::kSingularJacobian) << s.full_report();
  EXPECT_FALSE(s.usable());
}

TEST(ProjectedGaussNewton, ANonFiniteStartIsRefusedAndLeavesZ) {
  ExponentialFit fit = decay(2.0, 0.5);
  fit.y[3] = std::numeric_limits<double>::quiet_NaN();
  fit.z = Eigen::Vector2d(1.0, 0.1);
  const Summary s = ProjectedGaussNewton().minimise(fit);
  EXPECT_EQ(s.status, Status::kNonFinite);
  EXPECT_EQ(s.iterations, 0);
  EXPECT_EQ(fit.z, Eigen::Vector2d(1.0, 0.1));

  // Huge values: e^{−b t} overflows at b = −1e3 (V = inf) — the same refusal, not a crash.
  ExponentialFit huge = decay(2.0, 0.5);
  huge.z = Eigen::Vector2d(1.0, -1e3);
  EXPECT_EQ(ProjectedGaussNewton().minimise(huge).status, Status::kNonFinite);
}

TEST(ProjectedGaussNewton, OptionsValidateThemselves) {
  const auto refused = [](ProjectedGaussNewtonOptions o, const std::string& field) {
    try {
      ProjectedGaussNewton solver(o);
    } catch (const InvalidInput& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(field), std::string::npos) << what;
      return true;
    }
    return false;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(refused({.max_iterations = 0}, "ProjectedGaussNewtonOptions::max_iterations"));
  EXPECT_TRUE(refused({.step_tolerance = 0.0}, "ProjectedGaussNewtonOptions::step_tolerance"));
  EXPECT_TRUE(refused({.step_tolerance = nan}, "ProjectedGaussNewtonOptions::step_tolerance"));
  EXPECT_TRUE(refused({.cost_tolerance = -1.0}, "ProjectedGaussNewtonOptions::cost_tolerance"));
  ProjectedGaussNewtonOptions no_descent;
  no_descent.line_search.require_descent = false;  // the stop rules assume it
  EXPECT_TRUE(refused(no_descent, "require_descent"));
  ProjectedGaussNewtonOptions bad_shrink;
  bad_shrink.line_search.shrink = 1.0;
  EXPECT_TRUE(refused(bad_shrink, "LineSearch::shrink"));
}

}  // namespace
}  // namespace nlobs
