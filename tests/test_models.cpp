// Models layer: discretisations, adaptive integration, domain errors (through the harness's
// simulate()), the systems' equations.
#include <gtest/gtest.h>

#include <cmath>

#include "nlobs/models/modified_chua.hpp"
#include "nlobs/models/odeint_discretization.hpp"
#include "nlobs/models/systems.hpp"
#include "nlobs/observers/core/simulation.hpp"
#include "nlobs/solvers/status.hpp"

namespace nlobs {
namespace {

TEST(Models, DiscretisationsConverge) {
  // Harmonic oscillator over one period: RK4 error O(h^4), Euler O(h).
  const OscillatorNonlinearOutput osc;
  for (double h : {0.1, 0.05}) {
    const Discretized<OscillatorNonlinearOutput> euler(osc, h, Scheme::kEuler),
        rk4(osc, h, Scheme::kRk4);
    Eigen::Vector2d xe(1.0, 0.0), xr(1.0, 0.0);
    const long steps = std::lround(2.0 * M_PI / h);
    for (long k = 0; k < steps; ++k) {
      xe = euler.f(xe, {}, k);
      xr = rk4.f(xr, {}, k);
    }
    const double t = static_cast<double>(steps) * h;
    const Eigen::Vector2d exact(std::cos(t), -std::sin(t));
    EXPECT_LT((xr - exact).norm(), 1e-4) << h;
    EXPECT_GT((xe - exact).norm(), 100 * (xr - exact).norm()) << h;
  }
  EXPECT_THROW(Discretized<Duffing>(Duffing{}, 0.0), InvalidInput);  // the one exception type
}

// The flow over any interval (what observers of irregular samples integrate with): f on the
// grid bit for bit; over 2.5 h three equal RK4 steps, as accurate as the grid's (one period of
// the oscillator in 8 irregular intervals returns to the start); the adaptive flow agrees; a dt
// that is negative, not finite or beyond 1e9 steps is refused by name.
TEST(Models, FlowIntegratesOverAnyInterval) {
  const double h = 2.0 * M_PI / 40.0;
  const Discretized<OscillatorNonlinearOutput> rk4(OscillatorNonlinearOutput{}, h, Scheme::kRk4);
  const OdeintDiscretized<OscillatorNonlinearOutput> adaptive(OscillatorNonlinearOutput{}, h);
  const Eigen::Vector2d x0(1.0, 0.0);
  for (long k : {0L, 3L, 1000L}) {
    EXPECT_EQ(rk4.flow(x0, {}, static_cast<double>(k) * h, h), rk4.f(x0, {}, k));
  }
  const double intervals[] = {2.5, 0.3, 7.2, 1.0, 12.0, 0.5, 9.0, 7.5};  // in h: 40 in all
  Eigen::Vector2d xr = x0, xa = x0;
  double t = 0.0;
  for (const double in_steps : intervals) {
    xr = rk4.flow(xr, {}, t, in_steps * h);
    xa = adaptive.flow(xa, {}, t, in_steps * h);
    t += in_steps * h;
  }
  Eigen::Vector2d grid = x0;
  for (long k = 0; k < 40; ++k) grid = rk4.f(grid, {}, k);
  EXPECT_LT((xr - x0).norm(), 2.0 * (grid - x0).norm());  // substeps ≤ h: the grid's accuracy
  EXPECT_LT((xr - x0).norm(), 1e-4);
  EXPECT_LT((xa - x0).norm(), 1e-8);
  EXPECT_EQ(rk4.flow(x0, {}, 0.0, 0.0), x0);
  for (const double bad : {-h, std::nan(""), 2e9 * h}) {
    EXPECT_THROW(rk4.flow(x0, {}, 0.0, bad), InvalidInput) << bad;
  }
  EXPECT_THROW(adaptive.flow(x0, {}, 0.0, std::nan("")), InvalidInput);
}

TEST(Models, OdeintAdaptiveIntegrationIsAccurate) {
  // One period of the oscillator in 10 samples: dopri5 with tight tolerances is exact to
  // ~1e-9, where RK4 with the same sample step is off by ~1e-4.
  const double h = 2.0 * M_PI / 10.0;
  const OdeintDiscretized<OscillatorNonlinearOutput> adaptive(OscillatorNonlinearOutput{}, h);
  const Discretized<OscillatorNonlinearOutput> rk4(OscillatorNonlinearOutput{}, h, Scheme::kRk4);
  Eigen::Vector2d xa(1.0, 0.0), xr(1.0, 0.0);
  for (long k = 0; k < 10; ++k) {
    xa = adaptive.f(xa, {}, k);
    xr = rk4.f(xr, {}, k);
  }
  EXPECT_LT((xa - Eigen::Vector2d(1.0, 0.0)).norm(), 1e-8);
  EXPECT_GT((xr - Eigen::Vector2d(1.0, 0.0)).norm(), 1e-4);
  // Time-varying systems see the right t: the pendulum's friction c(t).
  const OdeintDiscretized<PendulumTimeVaryingFriction> pend(PendulumTimeVaryingFriction{}, 0.01);
  const Discretized<PendulumTimeVaryingFriction> pend_rk4(PendulumTimeVaryingFriction{}, 0.01,
                                                          Scheme::kRk4);
  Eigen::Vector2d pa(0.5, 0.0), pr(0.5, 0.0);
  for (long k = 0; k < 300; ++k) {
    pa = pend.f(pa, {}, k);
    pr = pend_rk4.f(pr, {}, k);
  }
  EXPECT_LT((pa - pr).norm(), 1e-7);
  EXPECT_THROW(OdeintDiscretized<Duffing>(Duffing{}, -1.0), InvalidInput);
  try {
    OdeintDiscretized<Duffing>(Duffing{}, 0.1, {.absolute_tolerance = std::nan("")});
    FAIL() << "accepted";
  } catch (const InvalidInput& e) {
    EXPECT_NE(
        std::string(e.what()).find("OdeintOptions::absolute_tolerance must be finite and > 0"),
        std::string::npos)
        << e.what();
  }
}

TEST(Models, LanderLeavesItsDomainWithAClearMessage) {
  LunarLander lander;
  const Discretized<LunarLander> model(lander, 0.01, Scheme::kRk4);
  SimulationOptions o;
  o.steps = 100000;
  o.sample_time = 0.01;
  o.input = [](long) { return Eigen::VectorXd::Constant(1, 1.0); };
  const Measurements m = simulate(model, Eigen::Vector3d(-700.0, 0.0, 1500.0), o);
  EXPECT_LT(m.steps(), 100000);
  EXPECT_NE(m.stop_message.find("mass x3"), std::string::npos) << m.stop_message;
  EXPECT_NE(m.stop_message.find("leaves its domain"), std::string::npos);
  EXPECT_GT(m.x.row(2).minCoeff(), 0.0);  // every recorded state is inside the domain
}

TEST(Models, SystemsMatchTheirEquations) {
  const Eigen::Vector3d x(0.3, -0.7, 1.1);
  const Eigen::Vector3d dl = Lorenz{}.vector_field(x, {}, 0.0);
  EXPECT_NEAR(dl[0], 10.0 * (-0.7 - 0.3), 1e-14);
  EXPECT_NEAR(dl[1], 0.3 * (28.0 - 1.1) + 0.7, 1e-14);
  EXPECT_NEAR(dl[2], 0.3 * -0.7 - 8.0 / 3.0 * 1.1, 1e-14);
  const Eigen::Vector3d dc = ChaoticNoLinear{}.vector_field(x, {}, 0.0);
  EXPECT_NEAR(dc[0], std::log(0.1 + std::exp(-1.0)), 1e-14);
  EXPECT_EQ(ChaoticNoLinear{}.h(x), Eigen::Vector2d(0.3, -0.7));
  const Eigen::Vector4d xr(0.1, 0.2, 0.3, 0.4);
  const Eigen::Vector4d dr =
      FlexibleJointRobot{}.vector_field(xr, Eigen::Matrix<double, 1, 1>(0.5), 0.0);
  EXPECT_NEAR(dr[1], -48.6 * 0.1 - 1.25 * 0.2 + 48.6 * 0.3 + 21.6 * 0.5, 1e-12);
  EXPECT_NEAR(dr[3], 19.5 * 0.1 - 19.5 * 0.3 - 3.33 * std::sin(0.3), 1e-12);
  EXPECT_NEAR(OscillatorNonlinearOutput{}.h(Eigen::Vector2d(0.5, 3.0))[0], 0.75, 1e-15);
}

}  // namespace
}  // namespace nlobs
