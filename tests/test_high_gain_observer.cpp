// High-gain observer in embedded coordinates ([HG-EMB23]): the observability maps by
// AD against the hand expansions, the α identities, the smooth saturation, the gains, and the
// observer's convergence and failure modes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "nlobs/models/discretization.hpp"
#include "nlobs/models/embedded_forms.hpp"
#include "nlobs/models/systems.hpp"
#include "nlobs/observers/core/simulation.hpp"
#include "nlobs/observers/high_gain/high_gain_observer.hpp"
#include "nlobs/observers/high_gain/lie_observability_map.hpp"
#include "nlobs/observers/high_gain/taylor_observability_map.hpp"
#include "short_tests.hpp"

namespace nlobs {
namespace {

// The options with the design, x̂(0) and (when given) ẑ(0) set.
HighGainOptions designed(HighGainOptions o, HighGainDesign d, const Eigen::VectorXd& xhat0,
                         std::optional<Eigen::VectorXd> zhat0 = {}) {
  o.design = std::move(d);
  o.initial_estimate = xhat0;
  o.initial_embedded_estimate = std::move(zhat0);
  return o;
}

template <typename Model>
Measurements simulate_continuous(const Model& model, const Eigen::VectorXd& x0, double step,
                                 double t_end) {
  SimulationOptions o;
  o.steps = std::lround(t_end / step) + 1;
  o.sample_time = step;
  return simulate(Discretized<Model>(model, step, Scheme::kRk4), x0, o);
}

// ‖q_N(x_k) − ẑ_k‖ and ‖x_k − x̂_k‖ per sample.
struct Trace {
  Eigen::VectorXd z_error, x_error;
  std::vector<std::string> failures;
};

template <typename Model>
Trace run(HighGainObserver<Model>& observer, const Measurements& data) {
  Trace t;
  t.z_error.resize(data.steps());
  t.x_error.resize(data.steps());
  for (Eigen::Index k = 0; k < data.steps(); ++k) {
    const ObserverStep& s = observer.step(k, data.t[k], data.y.col(k), data.u.col(k));
    if (!s.failure.empty()) t.failures.push_back(s.failure);
    t.z_error[k] = (observer.coordinates_at(data.x.col(k), data.t[k]) - observer.zhat()).norm();
    t.x_error[k] = (data.x.col(k) - s.estimate).norm();
  }
  return t;
}

// The largest value over samples at t >= from.
double max_after(const Eigen::VectorXd& v, const Measurements& data, double from) {
  double worst = 0.0;
  for (Eigen::Index k = 0; k < v.size(); ++k) {
    if (data.t[k] >= from && !(v[k] <= worst)) worst = v[k];
  }
  return worst;
}

std::vector<Eigen::VectorXd> random_points(int n, int count, double scale, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-scale, scale);
  std::vector<Eigen::VectorXd> points;
  for (int i = 0; i < count; ++i) {
    Eigen::VectorXd x(n);
    for (int j = 0; j < n; ++j) x[j] = u(rng);
    points.push_back(x);
  }
  return points;
}

// The two ways of building q_N from the model: ADOL-C tapes and Boost's Taylor polynomials.
enum class AdMap { kAdolc, kTaylor };

template <typename Model>
std::shared_ptr<ObservabilityMap> model_map(AdMap which, const Model& model, int N) {
  if (which == AdMap::kAdolc) return std::make_shared<LieObservabilityMap>(model, N);
  return make_taylor_observability_map(model, N);
}

// AD map (every N from 2 up, which includes ADOL-C's own lie_gradient's broken N = 2 case)
// against the hand expansion, values and Jacobians.
template <typename Form, typename Model>
void expect_maps_agree(AdMap which, const Model& model, double scale) {
  const ExplicitObservabilityMap<Form> hand;
  for (int N = std::max(2, Form::kStates); N <= Form::kDimension; ++N) {
    const std::shared_ptr<ObservabilityMap> map = model_map(which, model, N);
    const ObservabilityMap& ad = *map;
    for (const Eigen::VectorXd& x : random_points(Form::kStates, 20, scale, 7)) {
      Eigen::VectorXd za, zh;
      Eigen::MatrixXd ja, jh;
      ASSERT_TRUE(ad.value(x, za));
      ASSERT_TRUE(hand.value(x, zh));
      ASSERT_TRUE(ad.jacobian(x, ja));
      ASSERT_TRUE(hand.jacobian(x, jh));
      ASSERT_EQ(za.size(), N);
      ASSERT_EQ(ja.rows(), N);
      for (int j = 0; j < N; ++j) {
        const double tol = 1e-12 * (1.0 + std::abs(zh[j]) + jh.row(j).cwiseAbs().sum());
        EXPECT_NEAR(za[j], zh[j], tol)
            << ad.description() << ": z" << j + 1 << " at N = " << N << ", x = " << x.transpose();
        for (int i = 0; i < Form::kStates; ++i) {
          EXPECT_NEAR(ja(j, i), jh(j, i), tol * 10) << "dz" << j + 1 << "/dx" << i + 1;
        }
      }
    }
  }
}

TEST(ObservabilityMap, AdEqualsHandExpansions) {
  for (AdMap which : {AdMap::kAdolc, AdMap::kTaylor}) {
    expect_maps_agree<DuffingEmbedding>(which, Duffing{}, 1.5);
    expect_maps_agree<OscillatorEmbedding>(which, OscillatorNonlinearOutput{}, 1.0);
    expect_maps_agree<LorenzEmbedding>(which, Lorenz{}, 20.0);
    expect_maps_agree<VanDerPolEmbedding>(which, VanDerPol{}, 2.5);
  }
}

// d/dt z_N = L_f^N h(x) = α(q_N(x)) ([HG-EMB23]), and the gradients agree by the chain rule.
template <typename Form, typename Model>
void expect_alpha_identity(AdMap which, const Model& model, double scale) {
  constexpr int N = Form::kDimension;
  const std::shared_ptr<ObservabilityMap> map = model_map(which, model, N);
  const ObservabilityMap& ad = *map;
  const ExplicitObservabilityMap<Form> hand;
  const EmbeddedAlpha alpha = explicit_alpha<Form>();
  for (const Eigen::VectorXd& x : random_points(Form::kStates, 50, scale, 11)) {
    Eigen::VectorXd z, grad_alpha, grad_next;
    Eigen::MatrixXd dq;
    ASSERT_TRUE(hand.value(x, z));
    ASSERT_TRUE(hand.jacobian(x, dq));
    double next = 0.0;
    ASSERT_TRUE(ad.next(x, next, &grad_next));
    const double a = alpha.value(z);
    EXPECT_NEAR(next, a, 1e-11 * (1.0 + std::abs(a))) << "x = " << x.transpose();
    alpha.gradient(z, grad_alpha);
    const Eigen::VectorXd chain = dq.transpose() * grad_alpha;
    EXPECT_LT((grad_next - chain).norm(), 1e-10 * (1.0 + chain.norm())) << "x = " << x.transpose();
  }
}

TEST(ObservabilityMap, AlphaIdentitiesAtRandomStates) {
  for (AdMap which : {AdMap::kAdolc, AdMap::kTaylor}) {
    expect_alpha_identity<DuffingEmbedding>(which, Duffing{}, 1.5);
    expect_alpha_identity<OscillatorEmbedding>(which, OscillatorNonlinearOutput{}, 1.0);
  }
}

// L_f^N h without a hand α (Lorenz, Van der Pol): the two AD maps agree, value and gradient.
TEST(ObservabilityMap, TaylorAndAdolcAgreeOnLfNh) {
  const auto agree = [](const ObservabilityMap& a, const ObservabilityMap& b, double scale) {
    for (const Eigen::VectorXd& x : random_points(static_cast<int>(a.states()), 30, scale, 5)) {
      double va = 0.0, vb = 0.0, v_only = 0.0;
      Eigen::VectorXd ga, gb;
      ASSERT_TRUE(a.next(x, va, &ga));
      ASSERT_TRUE(b.next(x, vb, &gb));
      ASSERT_TRUE(a.next(x, v_only, nullptr));
      EXPECT_NEAR(va, vb, 1e-12 * (1.0 + std::abs(vb))) << "x = " << x.transpose();
      EXPECT_EQ(va, v_only);
      EXPECT_LT((ga - gb).norm(), 1e-12 * (1.0 + gb.norm())) << "x = " << x.transpose();
    }
  };
  agree(TaylorObservabilityMap<Lorenz, 4>{}, LieObservabilityMap(Lorenz{}, 4), 20.0);
  agree(TaylorObservabilityMap<VanDerPol, 5>{}, LieObservabilityMap(VanDerPol{}, 5), 2.5);
  agree(TaylorObservabilityMap<VanDerPol, 8>{}, LieObservabilityMap(VanDerPol{}, 8), 2.5);
}

// f with a value-dependent branch: ADOL-C's tape holds the branch it was recorded on, the
// Taylor map evaluates f afresh at each x. x1' = x2, x2' = −k x1 with k = 1 (x1 > 0) or 2,
// y = x1: q4 = (x1, x2, −k x1, −k x2).
struct SwitchedSpring : ModelSizes<2, 0, 1> {
  template <typename T>
  State<T> vector_field(const State<T>& x, const Input&, double) const {
    return State<T>(x[1], x[0] > 0.0 ? -x[0] : -2.0 * x[0]);
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return Output<T>(x[0]);
  }
};

TEST(ObservabilityMap, TaylorMapFollowsBranchesOfTheModel) {
  const TaylorObservabilityMap<SwitchedSpring, 4> map;
  for (double k : {1.0, 2.0}) {
    const Eigen::Vector2d x(k == 1.0 ? 0.7 : -0.7, 0.3);
    Eigen::VectorXd z;
    Eigen::MatrixXd dq;
    ASSERT_TRUE(map.value(x, z));
    ASSERT_TRUE(map.jacobian(x, dq));
    EXPECT_LT((z - Eigen::Vector4d(x[0], x[1], -k * x[0], -k * x[1])).norm(), 1e-15) << k;
    Eigen::Matrix<double, 4, 2> expected;
    expected << 1, 0, 0, 1, -k, 0, 0, -k;
    EXPECT_LT((dq - expected).norm(), 1e-15) << k;
    double next = 0.0;
    ASSERT_TRUE(map.next(x, next, nullptr));
    EXPECT_NEAR(next, k * k * x[0], 1e-15);  // L_f^4 h = k² x1
  }
}

TEST(ObservabilityMap, OscillatorInverseIsExactOnTheImage) {
  const OscillatorEmbedding form;
  for (const Eigen::VectorXd& x : random_points(2, 30, 1.0, 3)) {
    const Eigen::Vector2d back = form.inverse(form(Eigen::Vector2d(x)));
    EXPECT_LT((back - x).norm(), 1e-12);
  }
}

// A time-varying model (the pendulum's friction c(t)) has no autonomous q_N: refused.
TEST(ObservabilityMap, TimeVaryingModelsAreRefused) {
  try {
    LieObservabilityMap map(PendulumTimeVaryingFriction{}, 3);
    FAIL() << "accepted";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("depends on t"), std::string::npos) << e.what();
  }
  HighGainObserver<PendulumTimeVaryingFriction>::Design d;
  d.map = std::make_shared<ExplicitObservabilityMap<OscillatorEmbedding>>();
  d.alpha = explicit_alpha<OscillatorEmbedding>();
  HighGainOptions o;
  o.sample_time = 0.01;
  try {
    HighGainObserver<PendulumTimeVaryingFriction> observer({},
                                                           designed(o, d, Eigen::Vector2d::Zero()));
    FAIL() << "accepted";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("depends on t"), std::string::npos) << e.what();
  }
}

TEST(ObservabilityMap, TaylorBadInputNamesWhatIsWrong) {
  try {
    make_taylor_observability_map(Lorenz{}, 2);
    FAIL() << "N = 2 < n = 3 accepted";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("N = 2 outside 3..8"), std::string::npos) << e.what();
  }
  EXPECT_THROW(make_taylor_observability_map(Duffing{}, kMaxTaylorObservabilityOrder + 1),
               InvalidInput);
  for (int N = 2; N <= kMaxTaylorObservabilityOrder; ++N) {
    EXPECT_EQ(make_taylor_observability_map(Duffing{}, N)->dimension(), N);
  }
  EXPECT_THROW((TaylorObservabilityMap<PendulumTimeVaryingFriction, 3>{}), InvalidInput);
  const TaylorObservabilityMap<Duffing, 3> map;
  Eigen::VectorXd z, g;
  Eigen::MatrixXd dq;
  double next = 0.0;
  EXPECT_THROW(map.value(Eigen::Vector3d::Ones(), z), InvalidInput);
  EXPECT_THROW(map.jacobian(Eigen::Vector3d::Ones(), dq), InvalidInput);
  EXPECT_THROW(map.next(Eigen::Vector3d::Ones(), next, &g), InvalidInput);
  const Eigen::Vector2d nan(std::nan(""), 0.0);
  EXPECT_FALSE(map.value(nan, z));
  EXPECT_FALSE(map.jacobian(nan, dq));
  EXPECT_FALSE(map.next(nan, next, &g));
  EXPECT_FALSE(map.value(Eigen::Vector2d(1e200, 0.0), z));  // x1³ overflows in L_f h
}

TEST(ObservabilityMap, BadInputNamesWhatIsWrong) {
  try {
    LieObservabilityMap map(Lorenz{}, 2);
    FAIL() << "N = 2 < n = 3 accepted";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("N = 2"), std::string::npos) << e.what();
  }
  const LieObservabilityMap map(Duffing{}, 3);
  Eigen::VectorXd z;
  EXPECT_THROW(map.value(Eigen::Vector3d::Ones(), z), InvalidInput);
  EXPECT_FALSE(map.value(Eigen::Vector2d(std::nan(""), 0.0), z));
}

TEST(SmoothStep, ValuesAndContinuityAtOneAndB) {
  const double b = 4.0;
  EXPECT_EQ(smooth_step(0.3, b), 1.0);
  EXPECT_EQ(smooth_step(1.0, b), 1.0);
  EXPECT_EQ(smooth_step(b, b), 0.0);
  EXPECT_EQ(smooth_step(7.0, b), 0.0);
  EXPECT_NEAR(smooth_step(0.5 * (1.0 + b), b), 0.5, 1e-15);  // the symmetric midpoint
  double previous = 1.0;
  for (double x = 1.0; x <= b; x += 1e-3) {
    const double s = smooth_step(x, b);
    EXPECT_LE(s, previous + 1e-15) << "not decreasing at " << x;
    previous = s;
  }
  // Continuous with all derivatives flat at both ends: value and slope tend to the constants.
  using Jet = ceres::Jet<double, 1>;
  for (double d : {1e-1, 1e-2, 1e-3}) {
    const Jet near_one = smooth_step(Jet(1.0 + d, 0), b), near_b = smooth_step(Jet(b - d, 0), b);
    EXPECT_LT(1.0 - near_one.a, d) << d;
    EXPECT_LT(near_b.a, d) << d;
    EXPECT_LT(std::abs(near_one.v[0]), 1.0) << d;
    EXPECT_LT(std::abs(near_b.v[0]), 1.0) << d;
  }
  EXPECT_LT(1.0 - smooth_step(1.01, b), 1e-30);
  EXPECT_LT(smooth_step(b - 0.01, b), 1e-30);
}

TEST(SmoothSaturation, FactorIsOneInsideAndZeroBeyondRhoR) {
  SmoothSaturation s{Eigen::MatrixXd::Identity(2, 2) * 4.0, 1.0, 2.0};  // ‖z‖_P = 2 |z|
  s.validate(2);
  EXPECT_EQ(s.factor(Eigen::Vector2d(0.3, 0.3)), 1.0);      // ‖z‖_P = 0.85 ≤ R
  EXPECT_EQ(s.factor(Eigen::Vector2d(1.0, 0.0)), 0.0);      // ‖z‖_P = 2 = ρR
  const double mid = s.factor(Eigen::Vector2d(0.75, 0.0));  // ‖z‖_P = 1.5 between
  EXPECT_GT(mid, 0.0);
  EXPECT_LT(mid, 1.0);
}

TEST(SmoothSaturation, ValidateNamesTheField) {
  const auto message = [](SmoothSaturation s) {
    try {
      s.validate(2);
    } catch (const InvalidInput& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  Eigen::MatrixXd indefinite(2, 2);
  indefinite << 1, 2, 2, 1;
  EXPECT_NE(message({indefinite, 1.0, 2.0}).find("not positive definite"), std::string::npos);
  EXPECT_NE(message({Eigen::MatrixXd::Identity(3, 3), 1.0, 2.0}).find("P must be 2x2"),
            std::string::npos);
  Eigen::MatrixXd asymmetric = Eigen::MatrixXd::Identity(2, 2);
  asymmetric(0, 1) = 0.5;
  EXPECT_NE(message({asymmetric, 1.0, 2.0}).find("symmetric"), std::string::npos);
  EXPECT_NE(message({Eigen::MatrixXd::Identity(2, 2), 0.0, 2.0}).find("R must"), std::string::npos);
  EXPECT_NE(message({Eigen::MatrixXd::Identity(2, 2), 1.0, 1.0}).find("rho must"),
            std::string::npos);
}

// [HG-EMB23] §6: a box on x bounds z through q_N; P from it puts the box inside ‖z‖_P ≤ 1.
TEST(SmoothSaturation, BoxBoundEnclosesTheImage) {
  const Eigen::Vector2d X(1.5, 0.9);
  const Eigen::VectorXd Z = embedded_box_bound(DuffingEmbedding{}, X);
  const Eigen::MatrixXd P = saturation_weight_from_box(Z);
  const DuffingEmbedding q;
  double largest = 0.0;
  for (double a = -X[0]; a <= X[0]; a += X[0] / 50) {
    for (double b = -X[1]; b <= X[1]; b += X[1] / 50) {
      const Eigen::Matrix<double, 6, 1> z = q(Eigen::Vector2d(a, b));
      for (int j = 0; j < 6; ++j) ASSERT_LE(std::abs(z[j]), Z[j]) << "z" << j + 1;
      largest = std::max(largest, z.dot(P * z));
    }
  }
  EXPECT_LE(largest, 1.0);
  EXPECT_GT(largest, 0.01);  // not vacuous
  EXPECT_THROW(embedded_box_bound(DuffingEmbedding{}, Eigen::Vector2d(1.0, -1.0)), InvalidInput);
}

TEST(HighGainGains, CoefficientsFromPoles) {
  EXPECT_TRUE(hurwitz_coefficients({-1, -1, -1, -1}).isApprox(Eigen::Vector4d(1, 4, 6, 4)));
  EXPECT_TRUE(hurwitz_coefficients({-1, -2}).isApprox(Eigen::Vector2d(2, 3)));
  EXPECT_THROW(hurwitz_coefficients({-1, 0.5}), InvalidInput);
  const Eigen::VectorXcd roots = polynomial_roots(Eigen::Vector2d(2, 3));  // s² + 3s + 2
  EXPECT_NEAR(roots.real().minCoeff(), -2.0, 1e-12);
  EXPECT_NEAR(roots.real().maxCoeff(), -1.0, 1e-12);
}

using OscillatorObserver = HighGainObserver<OscillatorNonlinearOutput>;

OscillatorObserver::Design oscillator_design(bool inverse) {
  OscillatorObserver::Design d;
  d.map = std::make_shared<ExplicitObservabilityMap<OscillatorEmbedding>>();
  d.alpha = explicit_alpha<OscillatorEmbedding>();
  if (inverse) d.inverse = explicit_inverse<OscillatorEmbedding>();
  return d;
}

HighGainOptions oscillator_options(double h) {
  HighGainOptions o;
  o.sample_time = h;
  o.theta = 0.3;
  o.saturation =
      SmoothSaturation{Eigen::Vector4d(0.594, 0.421, 0.266, 0.153).asDiagonal(), 1.0, 2.0};
  return o;
}

TEST(HighGainObserver, GainsAreScaledHurwitzCoefficients) {
  HighGainOptions o = oscillator_options(0.01);
  o.theta = 0.5;
  const OscillatorObserver observer(
      OscillatorNonlinearOutput{},
      designed(o, oscillator_design(true), Eigen::Vector2d(-0.3, 0.0)));
  // (s + 1)^4: l = [1, 4, 6, 4]; k_i = l_{N−i} / θ^i
  EXPECT_TRUE(observer.gains().isApprox(Eigen::Vector4d(4 / 0.5, 6 / 0.25, 4 / 0.125, 1 / 0.0625)));
}

// The paper's oscillator example: x(0) = (−1/2, 0), error (0.2, 0), θ = 0.3, its P.
TEST(HighGainObserver, OscillatorConvergesWithTheExplicitInverse) {
  const double h = 0.005;
  const Measurements data =
      simulate_continuous(OscillatorNonlinearOutput{}, Eigen::Vector2d(-0.5, 0.0), h, 30.0);
  OscillatorObserver observer(
      OscillatorNonlinearOutput{},
      designed(oscillator_options(h), oscillator_design(true), Eigen::Vector2d(-0.3, 0.0)));
  EXPECT_EQ(observer.integrator(), HighGainIntegrator::kRk4);  // h·1/θ = 0.017
  const Trace t = run(observer, data);
  EXPECT_TRUE(t.failures.empty());
  EXPECT_GT(t.z_error[0], 0.1);
  EXPECT_LT(max_after(t.z_error, data, 20.0), 1e-6);  // measured: below 1e-6 from t = 16.9 s
  EXPECT_LT(max_after(t.x_error, data, 20.0), 1e-6);
  EXPECT_EQ(observer.jumps(), 0);
}

TEST(HighGainObserver, ProjectionByCeresMatchesTheInverse) {
  const double h = 0.005;
  const Measurements data =
      simulate_continuous(OscillatorNonlinearOutput{}, Eigen::Vector2d(-0.5, 0.0), h, 25.0);
  OscillatorObserver observer(
      OscillatorNonlinearOutput{},
      designed(oscillator_options(h), oscillator_design(false), Eigen::Vector2d(-0.3, 0.0)));
  const Trace t = run(observer, data);
  EXPECT_TRUE(t.failures.empty());
  EXPECT_LT(max_after(t.x_error, data, 20.0), 1e-6);
  EXPECT_LT(observer.projection_residual(), 1e-6);
}

TEST(HighGainObserver, CvodeAgreesWithRk4) {
  const double h = 0.005;
  const Measurements data =
      simulate_continuous(OscillatorNonlinearOutput{}, Eigen::Vector2d(-0.5, 0.0), h, 22.0);
  HighGainOptions o = oscillator_options(h);
  o.integrator = HighGainIntegrator::kRk4;
  OscillatorObserver explicit_steps(
      OscillatorNonlinearOutput{},
      designed(o, oscillator_design(true), Eigen::Vector2d(-0.3, 0.0)));
  o.integrator = HighGainIntegrator::kCvode;
  OscillatorObserver implicit(OscillatorNonlinearOutput{},
                              designed(o, oscillator_design(true), Eigen::Vector2d(-0.3, 0.0)));
  double largest_gap = 0.0;
  for (Eigen::Index k = 0; k < data.steps(); ++k) {
    ASSERT_TRUE(explicit_steps.step(k, data.t[k], data.y.col(k), data.u.col(k)).failure.empty());
    ASSERT_TRUE(implicit.step(k, data.t[k], data.y.col(k), data.u.col(k)).failure.empty());
    largest_gap = std::max(largest_gap, (implicit.zhat() - explicit_steps.zhat()).norm());
  }
  EXPECT_LT(largest_gap, 1e-6);  // both solve the same ODE (RK4 at h·|p|/θ = 0.017)
  EXPECT_LT((implicit.coordinates_at(data.x.col(data.steps() - 1), 0.0) - implicit.zhat()).norm(),
            1e-6);
}

// CVODE with α = L_f^N h: the prediction x̄ and its Jacobian rows are in the implicit system.
TEST(HighGainObserver, CvodeWithLieAlphaMatchesRk4) {
  const double h = 1e-3;
  const Measurements data = simulate_continuous(Lorenz{}, Eigen::Vector3d(1.0, 1.0, 20.0), h, 0.3);
  HighGainObserver<Lorenz>::Design d;
  d.map = std::make_shared<TaylorObservabilityMap<Lorenz, 4>>();
  HighGainOptions o;
  o.sample_time = h;
  o.theta = 0.05;
  o.integrator = HighGainIntegrator::kRk4;
  o.substeps = 20;  // the reference: RK4 converged in the step
  HighGainObserver<Lorenz> rk4(Lorenz{}, designed(o, d, Eigen::Vector3d(2.0, 3.0, 25.0)));
  o.integrator = HighGainIntegrator::kCvode;
  o.substeps = 1;
  HighGainObserver<Lorenz> cvode(Lorenz{}, designed(o, d, Eigen::Vector3d(2.0, 3.0, 25.0)));
  double worst = 0.0;
  for (Eigen::Index k = 0; k < data.steps(); ++k) {
    ASSERT_TRUE(rk4.step(k, data.t[k], data.y.col(k), data.u.col(k)).failure.empty());
    ASSERT_TRUE(cvode.step(k, data.t[k], data.y.col(k), data.u.col(k)).failure.empty());
    worst = std::max(worst, (cvode.zhat() - rk4.zhat()).norm() / (1.0 + rk4.zhat().norm()));
  }
  EXPECT_LT(worst, 1e-6);
}

// A sample CVODE cannot integrate past: an error for that sample, ẑ kept, and the sample does
// not poison the interpolation of the next ones.
TEST(HighGainObserver, CvodeFailureKeepsTheStateAndRecovers) {
  const double h = 0.01;
  const Measurements data =
      simulate_continuous(OscillatorNonlinearOutput{}, Eigen::Vector2d(-0.5, 0.0), h, 1.0);
  HighGainOptions o = oscillator_options(h);
  o.integrator = HighGainIntegrator::kCvode;
  OscillatorObserver observer(OscillatorNonlinearOutput{},
                              designed(o, oscillator_design(true), Eigen::Vector2d(-0.3, 0.0)));
  for (Eigen::Index k = 0; k < 50; ++k) observer.step(k, data.t[k], data.y.col(k), data.u.col(k));
  const Eigen::VectorXd before = observer.zhat();
  const ObserverStep& bad =
      observer.step(50, data.t[50], Eigen::VectorXd::Constant(1, 1e300), data.u.col(50));
  EXPECT_EQ(bad.failure, "non_finite");
  EXPECT_FALSE(bad.failure_message.empty());
  EXPECT_EQ(observer.zhat(), before);
  for (Eigen::Index k = 51; k < 60; ++k) {
    EXPECT_TRUE(observer.step(k, data.t[k], data.y.col(k), data.u.col(k)).failure.empty()) << k;
  }
}

// [HG-EMB23]'s hard start: ẑ(0) = q6(0, 0) while x circles the equilibrium (1, 0).
TEST(HighGainObserver, DuffingConvergesFromTheHardStart) {
  const double h = 1e-3;
  const Measurements data = simulate_continuous(Duffing{}, Eigen::Vector2d(1.2, 0.0), h, 12.0);
  HighGainObserver<Duffing>::Design d;
  d.map = std::make_shared<ExplicitObservabilityMap<DuffingEmbedding>>();
  d.alpha = explicit_alpha<DuffingEmbedding>();
  HighGainOptions o;
  o.sample_time = h;
  o.theta = 0.1;
  Eigen::VectorXd P(6);
  P << 0.8, 0.145, 0.103, 0.0158, 4.07e-3, 5.26e-4;
  o.saturation = SmoothSaturation{P.asDiagonal(), 1.0, 2.0};
  HighGainObserver<Duffing> observer(Duffing{}, designed(o, d, Eigen::Vector2d::Zero()));
  EXPECT_TRUE(observer.zhat().isZero());  // q6(0, 0) = 0
  const Trace t = run(observer, data);
  EXPECT_TRUE(t.failures.empty());
  EXPECT_GT(t.z_error[0], 10.0);
  EXPECT_LT(max_after(t.z_error, data, 10.5), 1e-6);  // measured: below 1e-6 from t = 9.0 s
  EXPECT_LT(max_after(t.x_error, data, 10.5), 1e-7);
}

// α = L_f^N h along the prediction: Lorenz (N = 4) and Van der Pol (N = 5) converge to the
// floor the sampling sets (docs/observers.md), not to zero.
TEST(HighGainObserver, LorenzWithLieAlphaTracksAwayFromTheAxis) {
  const double h = 1e-3;
  const Measurements data = simulate_continuous(Lorenz{}, Eigen::Vector3d(1.0, 1.0, 20.0), h, 8.0);
  HighGainObserver<Lorenz>::Design d;
  d.map = std::make_shared<TaylorObservabilityMap<Lorenz, 4>>();
  HighGainOptions o;
  o.sample_time = h;
  o.theta = 0.02;
  o.saturation = SmoothSaturation{saturation_weight_from_box(embedded_box_bound(
                                      LorenzEmbedding{}, Eigen::Vector3d(25, 30, 55))),
                                  1.0, 2.0};
  HighGainObserver<Lorenz> observer(Lorenz{}, designed(o, d, Eigen::Vector3d(2.0, 3.0, 25.0)));
  const Trace t = run(observer, data);
  EXPECT_TRUE(t.failures.empty());
  double sum = 0.0;
  long count = 0;
  for (Eigen::Index k = 0; k < data.steps(); ++k) {
    if (data.t[k] >= 2.5) sum += t.x_error[k] * t.x_error[k], ++count;
  }
  EXPECT_LT(std::sqrt(sum / static_cast<double>(count)), 0.05);  // measured 0.031
  EXPECT_GT(t.x_error[0], 5.0);
}

// The observer does not care which AD map it runs on: the same run up to rounding.
TEST(HighGainObserver, TaylorAndAdolcMapsGiveTheSameRun) {
  const double h = 1e-3;
  // 0.5 s; 0.15 s under the sanitizers (ADOL-C is slow there), which still holds the transient
  // that the comparison and `moved` are about.
  const double horizon = test::short_tests() ? 0.15 : 0.5;
  const Measurements data =
      simulate_continuous(Lorenz{}, Eigen::Vector3d(1.0, 1.0, 20.0), h, horizon);
  HighGainOptions o;
  o.sample_time = h;
  o.theta = 0.02;
  HighGainObserver<Lorenz>::Design taylor, adolc;
  taylor.map = std::make_shared<TaylorObservabilityMap<Lorenz, 4>>();
  adolc.map = std::make_shared<LieObservabilityMap>(Lorenz{}, 4);
  HighGainObserver<Lorenz> a(Lorenz{}, designed(o, taylor, Eigen::Vector3d(2.0, 3.0, 25.0)));
  HighGainObserver<Lorenz> b(Lorenz{}, designed(o, adolc, Eigen::Vector3d(2.0, 3.0, 25.0)));
  double worst = 0.0, worst_z = 0.0, moved = 0.0;
  for (Eigen::Index k = 0; k < data.steps(); ++k) {
    const Eigen::VectorXd xa = a.step(k, data.t[k], data.y.col(k), data.u.col(k)).estimate;
    const Eigen::VectorXd xb = b.step(k, data.t[k], data.y.col(k), data.u.col(k)).estimate;
    worst = std::max(worst, (xa - xb).norm() / (1.0 + xb.norm()));
    worst_z = std::max(worst_z, (a.zhat() - b.zhat()).norm() / (1.0 + b.zhat().norm()));
    moved = std::max(moved, (xa - Eigen::Vector3d(2.0, 3.0, 25.0)).norm());
  }
  // Measured 5.8e-10 in ẑ; x̂ = argmin ‖ẑ − q4(x)‖ amplifies it to 3.9e-8 during the transient,
  // where ẑ is off q4's image and the minimum is flat.
  EXPECT_LT(worst_z, 1e-8);
  EXPECT_LT(worst, 1e-6);
  EXPECT_GT(moved, 1.0);  // a real transient, not two idle observers
}

TEST(HighGainObserver, LieAlphaIsSwitchedOffOnTheNonObservableSet) {
  HighGainObserver<Lorenz>::Design d;
  d.map = std::make_shared<LieObservabilityMap>(Lorenz{}, 4);
  HighGainOptions o;
  o.sample_time = 1e-3;
  o.theta = 0.05;
  HighGainObserver<Lorenz> on_axis(Lorenz{}, designed(o, d, Eigen::Vector3d(0.0, 0.0, 10.0)));
  const ObserverStep& s = on_axis.step(0, 0.0, Eigen::VectorXd::Zero(1), Eigen::VectorXd());
  EXPECT_LT(s.signals[6], 1e-12);  // alpha_weight: ∂q_4/∂x3 = 0 on the x3 axis
  HighGainObserver<Lorenz> off_axis(Lorenz{}, designed(o, d, Eigen::Vector3d(5.0, 5.0, 10.0)));
  const ObserverStep& s2 =
      off_axis.step(0, 0.0, Eigen::VectorXd::Constant(1, 5.0), Eigen::VectorXd());
  EXPECT_GT(s2.signals[6], 0.99);
}

TEST(HighGainObserver, VanDerPolWithLieAlphaConverges) {
  const double h = 1e-3;
  const Measurements data = simulate_continuous(VanDerPol{}, Eigen::Vector2d(2.0, 0.0), h, 4.0);
  HighGainObserver<VanDerPol>::Design d;
  d.map = std::make_shared<TaylorObservabilityMap<VanDerPol, 5>>();
  HighGainOptions o;
  o.sample_time = h;
  o.theta = 0.02;
  o.saturation = SmoothSaturation{
      saturation_weight_from_box(embedded_box_bound(VanDerPolEmbedding{}, Eigen::Vector2d(2.5, 3))),
      1.0, 2.0};
  HighGainObserver<VanDerPol> observer(VanDerPol{}, designed(o, d, Eigen::Vector2d(1.0, 1.0)));
  const Trace t = run(observer, data);
  EXPECT_TRUE(t.failures.empty());
  EXPECT_LT(max_after(t.x_error, data, 2.0), 1e-3);  // measured 7.1e-5
}

// Missing samples after convergence are bridged: the error right after the gap stays small.
TEST(HighGainObserver, MissingSamplesAreBridged) {
  const double h = 0.005;
  Measurements data =
      simulate_continuous(OscillatorNonlinearOutput{}, Eigen::Vector2d(-0.5, 0.0), h, 25.0);
  for (Eigen::Index k = 4400; k < 4410; ++k) data.y(0, k) = std::nan("");  // t = 22–22.05 s
  OscillatorObserver observer(
      OscillatorNonlinearOutput{},
      designed(oscillator_options(h), oscillator_design(true), Eigen::Vector2d(-0.3, 0.0)));
  long missing = 0;
  double after_gap = 0.0;
  for (Eigen::Index k = 0; k < data.steps(); ++k) {
    missing +=
        observer.step(k, data.t[k], data.y.col(k), data.u.col(k)).measurement_missing ? 1 : 0;
    if (k >= 4410 && k < 4430) {
      after_gap = std::max(after_gap, (data.x.col(k) - observer.xhat()).norm());
    }
  }
  EXPECT_EQ(missing, 10);
  EXPECT_LT(after_gap, 1e-5);
  EXPECT_LT((data.x.col(data.steps() - 1) - observer.xhat()).norm(), 1e-6);
}

// With an explicit α the model's prediction only warm-starts the projection: from an x̂ where
// the prediction overflows (Duffing at x̂ = (1e100, 0); the projection fails there and keeps
// x̂ until the fifth sample's restart from the origin) the observer keeps integrating ẑ
// instead of failing every step, and converges.
TEST(HighGainObserver, ABlownUpPredictionDoesNotStopAnExplicitAlpha) {
  const double h = 1e-3;
  const Measurements data = simulate_continuous(Duffing{}, Eigen::Vector2d(1.2, 0.0), h, 12.0);
  HighGainObserver<Duffing>::Design d;
  d.map = std::make_shared<ExplicitObservabilityMap<DuffingEmbedding>>();
  d.alpha = explicit_alpha<DuffingEmbedding>();
  HighGainOptions o;
  o.sample_time = h;
  o.theta = 0.1;
  Eigen::VectorXd P(6);
  P << 0.8, 0.145, 0.103, 0.0158, 4.07e-3, 5.26e-4;
  o.saturation = SmoothSaturation{P.asDiagonal(), 1.0, 2.0};
  o.restart_every = 5;
  HighGainObserver<Duffing> observer(
      Duffing{}, designed(o, d, Eigen::Vector2d(1e100, 0.0), Eigen::VectorXd::Zero(6)));
  const Trace t = run(observer, data);
  EXPECT_TRUE(std::find(t.failures.begin(), t.failures.end(), "non_finite") == t.failures.end());
  EXPECT_LT(max_after(t.z_error, data, 10.5), 1e-6);
  EXPECT_LT(max_after(t.x_error, data, 10.5), 1e-6);
}

TEST(HighGainObserver, SamplesMustArriveInOrder) {
  OscillatorObserver observer(
      OscillatorNonlinearOutput{},
      designed(oscillator_options(0.01), oscillator_design(true), Eigen::Vector2d(-0.3, 0.0)));
  const Eigen::VectorXd y = Eigen::VectorXd::Constant(1, -0.25), none(0);
  observer.step(0, 0.0, y, none);
  observer.step(1, 0.01, y, none);
  EXPECT_THROW(observer.step(1, 0.01, y, none), InvalidInput);
  EXPECT_EQ(observer.step(2, 0.025, y, none).failure, "non_uniform");  // between grid points
  EXPECT_TRUE(observer.step(2, 0.02, y, none).failure.empty());
}

// A map that stops giving finite values when told to: the projection's failure keeps x̂.
class FailingMap final : public ObservabilityMap {
 public:
  bool broken = false;
  Eigen::Index states() const override { return 2; }
  Eigen::Index dimension() const override { return 4; }
  std::string description() const override { return "failing"; }
  bool value(const Eigen::VectorXd& x, Eigen::VectorXd& z) const override {
    if (broken) return false;
    return inner_.value(x, z);
  }
  bool jacobian(const Eigen::VectorXd& x, Eigen::MatrixXd& dq) const override {
    return inner_.jacobian(x, dq) && !broken;
  }

 private:
  ExplicitObservabilityMap<OscillatorEmbedding> inner_;
};

TEST(HighGainObserver, FailedProjectionKeepsThePreviousEstimate) {
  const double h = 0.01;
  const Measurements data =
      simulate_continuous(OscillatorNonlinearOutput{}, Eigen::Vector2d(-0.5, 0.0), h, 1.0);
  auto map = std::make_shared<FailingMap>();
  OscillatorObserver::Design d;
  d.map = map;
  d.alpha = explicit_alpha<OscillatorEmbedding>();
  OscillatorObserver observer(OscillatorNonlinearOutput{},
                              designed(oscillator_options(h), d, Eigen::Vector2d(-0.3, 0.0)));
  for (Eigen::Index k = 0; k < 50; ++k) observer.step(k, data.t[k], data.y.col(k), data.u.col(k));
  const Eigen::Vector2d before = observer.xhat();
  map->broken = true;
  const ObserverStep& s = observer.step(50, data.t[50], data.y.col(50), data.u.col(50));
  EXPECT_EQ(s.failure, "projection");
  EXPECT_NE(s.failure_message.find("x̂ kept"), std::string::npos) << s.failure_message;
  EXPECT_EQ(s.estimate, Eigen::VectorXd(before));
}

// An embedding too short to be injective (N = 1 < n = 2).
struct ShortMap {
  static constexpr int kStates = 2, kDimension = 1;
  template <typename T>
  Eigen::Matrix<T, 1, 1> operator()(const Eigen::Matrix<T, 2, 1>& x) const {
    return Eigen::Matrix<T, 1, 1>(x[0]);
  }
};

// Two coordinates of a three-state system: never injective.
struct TwoOfThree {
  static constexpr int kStates = 3, kDimension = 2;
  template <typename T>
  Eigen::Matrix<T, 2, 1> operator()(const Eigen::Matrix<T, 3, 1>& x) const {
    return Eigen::Matrix<T, 2, 1>(x[0], x[1]);
  }
};

TEST(HighGainObserver, BadOptionsAreErrorsNamingTheOption) {
  const auto message = [](HighGainOptions o, OscillatorObserver::Design d) {
    try {
      OscillatorObserver observer(OscillatorNonlinearOutput{},
                                  designed(std::move(o), std::move(d), Eigen::Vector2d(-0.3, 0.0)));
    } catch (const InvalidInput& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const HighGainOptions good = oscillator_options(0.01);
  EXPECT_EQ(message(good, oscillator_design(true)), "accepted");
  HighGainOptions o = good;
  o.theta = 0.0;
  EXPECT_NE(message(o, oscillator_design(true)).find("theta"), std::string::npos);
  o = good;
  o.theta = -1.0;
  EXPECT_NE(message(o, oscillator_design(true)).find("theta"), std::string::npos);
  o = good;
  o.coefficients = Eigen::Vector4d(1, -4, 6, 4);  // s⁴ + 4s³ + 6s² − 4s + 1: unstable roots
  EXPECT_NE(message(o, oscillator_design(true)).find("not Hurwitz"), std::string::npos);
  o = good;
  o.poles = {-1, -1, 2, -1};
  EXPECT_NE(message(o, oscillator_design(true)).find("poles"), std::string::npos);
  o = good;
  o.poles = {-1, -1};
  EXPECT_NE(message(o, oscillator_design(true)).find("poles must list N = 4"), std::string::npos);
  o = good;
  o.saturation->P(0, 0) = -1.0;
  EXPECT_NE(message(o, oscillator_design(true)).find("saturation"), std::string::npos);
  o = good;
  o.sample_time = 0.0;
  EXPECT_NE(message(o, oscillator_design(true))
                .find("HighGainOptions::sample_time must be finite and > 0 (got 0)"),
            std::string::npos);
  o = good;
  o.residual_scale = 0.0;
  EXPECT_NE(message(o, oscillator_design(true)).find("residual_scale"), std::string::npos);
  o = good;
  o.restart_every = 0;
  EXPECT_NE(message(o, oscillator_design(true))
                .find("HighGainOptions::restart_every must be >= 1 (got 0)"),
            std::string::npos);
  o = good;
  o.name.clear();
  EXPECT_NE(message(o, oscillator_design(true)).find("HighGainOptions::name"), std::string::npos);
  o = good;
  try {  // ẑ(0) of N = 3 for N = 4 (designed() sets it; message() would reset it)
    OscillatorObserver observer(OscillatorNonlinearOutput{},
                                designed(good, oscillator_design(true), Eigen::Vector2d(-0.3, 0.0),
                                         Eigen::VectorXd(Eigen::Vector3d::Zero())));
    ADD_FAILURE() << "accepted";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "HighGainOptions::initial_embedded_estimate must have 4 entries (got 3)"),
              std::string::npos)
        << e.what();
  }
  EXPECT_NE(message(good, OscillatorObserver::Design{}).find("HighGainOptions::design.map"),
            std::string::npos);
  o = good;
  o.theta = 1e-80;
  EXPECT_NE(message(o, oscillator_design(true)).find("overflow"), std::string::npos);
  // No α and a map that cannot give L_f^N h.
  OscillatorObserver::Design no_alpha = oscillator_design(true);
  no_alpha.alpha = {};
  EXPECT_NE(message(good, no_alpha).find("no α"), std::string::npos);
  // N = 1: no map of one coordinate is injective (validate()).
  OscillatorObserver::Design short_map = oscillator_design(true);
  short_map.map = std::make_shared<ExplicitObservabilityMap<ShortMap>>();
  EXPECT_NE(message(good, short_map).find("HighGainOptions::design.map must have N >= 2"),
            std::string::npos);
  // N = 2 < n = 3 (Lorenz): valid options, refused against the model (the constructor).
  HighGainOptions lorenz = good;
  lorenz.saturation.reset();
  lorenz.design.map = std::make_shared<ExplicitObservabilityMap<TwoOfThree>>();
  lorenz.design.alpha =
      EmbeddedAlpha{[](const Eigen::VectorXd&) { return 0.0; },
                    [](const Eigen::VectorXd&, Eigen::VectorXd& g) { g.setZero(); }};
  lorenz.initial_estimate = Eigen::Vector3d(1.0, 1.0, 20.0);
  EXPECT_NO_THROW(lorenz.validate());
  try {
    HighGainObserver<Lorenz> refused(Lorenz{}, lorenz);
    ADD_FAILURE() << "accepted";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("N = 2 is smaller than the state dimension n = 3"),
              std::string::npos)
        << e.what();
  }
  o = good;
  o.jump_threshold = std::numeric_limits<double>::infinity();  // count no jump: allowed
  o.observability_floor = std::numeric_limits<double>::infinity();
  EXPECT_EQ(message(o, oscillator_design(true)), "accepted");
  o.jump_threshold = 0.0;
  EXPECT_NE(message(o, oscillator_design(true))
                .find("HighGainOptions::jump_threshold must be > 0 (+inf: count no jump) (got 0)"),
            std::string::npos);
}

// The projection engine is an object: a square-only one cannot project N = 4 onto n = 2, an
// engine beside an explicit inverse is ambiguous, and the report names the engine it was given.
TEST(HighGainObserverBadInput, TheProjectionEngineIsChecked) {
  const auto with = [](OscillatorObserver::Design d, const std::string& spec) {
    try {
      OscillatorObserver observer(
          OscillatorNonlinearOutput{},
          designed(oscillator_options(0.01), std::move(d), Eigen::Vector2d(-0.3, 0.0)),
          EngineRegistry<2>::global().create(spec, high_gain_projection_options()));
      return "accepted: " + observer.info().engine;
    } catch (const InvalidInput& e) {
      return std::string(e.what());
    }
  };
  EXPECT_NE(with(oscillator_design(false), "newton").find("'newton' solves square systems only"),
            std::string::npos);
  EXPECT_NE(with(oscillator_design(true), "ceres").find("both an explicit inverse"),
            std::string::npos);
  EXPECT_EQ(with(oscillator_design(false), "ceres:max_iter=50"), "accepted: ceres:max_iter=50");
  // Without an engine: Ceres, or the explicit inverse when there is one.
  EXPECT_EQ(OscillatorObserver(OscillatorNonlinearOutput{},
                               designed(oscillator_options(0.01), oscillator_design(false),
                                        Eigen::Vector2d(-0.3, 0.0)))
                .info()
                .engine,
            "ceres");
  EXPECT_EQ(OscillatorObserver(OscillatorNonlinearOutput{},
                               designed(oscillator_options(0.01), oscillator_design(true),
                                        Eigen::Vector2d(-0.3, 0.0)))
                .info()
                .engine,
            "explicit inverse");
}

}  // namespace
}  // namespace nlobs
