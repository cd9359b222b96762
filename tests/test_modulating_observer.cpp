// The modulating-function observer ([MF-LTV]): kernels' boundary conditions and
// exactness, the observer's exactness one horizon after start, its noise advantage over finite
// differences, the sampled-data mode, Theorem 1's disturbance bound and the failure modes.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "nlobs/models/discretization.hpp"
#include "nlobs/observers/baselines/finite_difference_observer.hpp"
#include "nlobs/observers/core/simulation.hpp"
#include "nlobs/observers/modulating/modulating_function_observer.hpp"
#include "nlobs/solvers/engine_registry.hpp"
#include "test_support.hpp"

namespace nlobs {
namespace {

using test::message_of;

template <typename Model>
Measurements simulate_continuous(const Model& model, const Eigen::VectorXd& x0, double step,
                                 double t_end, double noise = 0.0) {
  SimulationOptions o;
  o.steps = std::lround(t_end / step) + 1;
  o.sample_time = step;
  o.noise_std = noise;
  o.seed = 7;
  return simulate(Discretized<Model>(model, step, Scheme::kRk4), x0, o);
}

// y⁽ᴺ⁾ = v: the pure integrator chain, x = (y, y', …, y⁽ᴺ⁻¹⁾), v = u (or 0). η_j = y⁽ᴺ⁻¹⁻ʲ⁾.
template <int N>
struct ChainForm {
  static constexpr int n = N, p = 1, state_size = N;
  void coefficients(double, Vector<N>& a, Matrix<N, 1>& b) const {
    a.setZero();
    b.setZero();
    b(0, 0) = 1.0;
  }
  Vector<1> inputs(double, double, const Eigen::VectorXd& u) const {
    return Vector<1>(u.size() ? u[0] : 0.0);
  }
  Vector<N> canonical(double, const Vector<N>& x) const { return x.reverse(); }
  Vector<N> state(double, const Vector<N>& eta) const { return eta.reverse(); }
};

// x̂(0) = 0 for a form of `states` states (the LTI and pendulum forms have 2).
ModulatingOptions options(double delta, double T, Eigen::Index states = 2) {
  ModulatingOptions o;
  o.initial_estimate = Eigen::VectorXd::Zero(states);
  o.sample_time = delta;
  o.horizon = T;
  return o;
}

// Largest ‖η(x_k) − η̂_k‖ / max ‖η‖ over k ≥ from, and the failures seen.
template <typename Form>
double relative_error_from(ModulatingFunctionObserver<Form>& observer, const Measurements& data,
                           Eigen::Index from, int* failures = nullptr) {
  double worst = 0.0, scale = 0.0;
  for (Eigen::Index k = 0; k < data.steps(); ++k) {
    const ObserverStep& s = observer.step(k, data.t[k], data.y.col(k), data.u.col(k));
    if (failures && !s.failure.empty()) ++*failures;
    const Eigen::VectorXd eta = observer.coordinates_at(data.x.col(k), data.t[k]);
    scale = std::max(scale, eta.norm());
    if (k >= from) {
      const double e = (eta - Eigen::VectorXd(observer.eta())).norm();
      if (!(e <= worst)) worst = e;
    }
  }
  return worst / scale;
}

double derivative_rms(Observer& observer, const Measurements& data, Eigen::Index from) {
  double sum = 0.0;
  for (Eigen::Index k = 0; k < data.steps(); ++k) {
    const ObserverStep& s = observer.step(k, data.t[k], data.y.col(k), data.u.col(k));
    if (k >= from) sum += std::pow(s.estimate[1] - data.x(1, k), 2);
  }
  return std::sqrt(sum / static_cast<double>(data.steps() - from));
}

TEST(ModulatingKernels, BoundaryConditionsHold) {
  for (int n = 1; n <= 4; ++n) {
    for (int extra_order : {0, 2}) {
      for (int extra_degree : {0, 3}) {
        for (double T : {0.5, 1.0, 2.0}) {
          ModulatingKernelOptions o;
          o.order = n + extra_order;
          o.degree = o.order + n - 1 + extra_degree;
          const ModulatingKernels K(n, T, o);
          // The left-end conditions hold by construction (c_k = 0 for k < r); the right-end
          // ones come out of the solve and the long-double refinement.
          for (int j = 0; j < n; ++j) {
            for (int k = 0; k < n; ++k) {
              // φ⁽ᵏ⁾(T) carries T^{−k} from the σ-scaling: compare relative to that scale.
              EXPECT_NEAR(K.value(j, k, T) * std::pow(T, k - j), k == j ? 1.0 : 0.0, 1e-12)
                  << "n " << n << " j " << j << " k " << k << " T " << T;
            }
          }
        }
      }
    }
  }
}

// With y⁽ⁿ⁾ = 0 (a polynomial of degree < n) the kernels give y⁽ⁿ⁻¹⁻ʲ⁾(t) exactly:
// η_j = (−1)^{j+1+n} ∫ φ_j⁽ⁿ⁾ y, integrated here by composite Simpson on 2000 panels (its error
// on these low-degree integrands is far below the tolerance).
TEST(ModulatingKernels, ExactOnPolynomialsBelowTheOrder) {
  const int n = 3;
  const double T = 0.8, t = 2.0;
  for (int extra_degree : {0, 4}) {
    ModulatingKernelOptions o;
    o.degree = 2 * n - 1 + extra_degree;
    const ModulatingKernels K(n, T, o);
    // y = 1 − 2τ + 0.7τ², on [t − T, t].
    const auto y = [](double tau) { return 1.0 - 2.0 * tau + 0.7 * tau * tau; };
    const double expected[3] = {1.4, -2.0 + 1.4 * t, y(t)};  // η_0 = y'', η_1 = y', η_2 = y
    for (int j = 0; j < n; ++j) {
      const int panels = 2000;
      const double h = T / panels;
      double sum = 0.0;
      for (int m = 0; m <= panels; ++m) {
        const double w = (m == 0 || m == panels) ? 1.0 : (m % 2 ? 4.0 : 2.0);
        const double s = m * h;
        sum += w * K.value(j, n, s) * y(t - T + s);
      }
      sum *= h / 3.0;
      const double eta = ((j + 1 + n) % 2 ? -1.0 : 1.0) * sum;
      EXPECT_NEAR(eta, expected[j], 1e-9) << "j " << j << " degree " << o.degree;
    }
  }
}

// For ā = 0 the minimal kernel is already optimal (the Hermite cubic minimises ∫ (φ'')², the
// spline property), so extra degrees pay only through ā ≠ 0 or a smoother left end (order r > n,
// whose minimal kernel is the unique one of its degree, not the best of a higher one). Measured
// √J: order 2: 3.1259 → 3.1252 (η_0), 1.8100 → 1.8087 (η_1); order 3: 4.073 → 3.194, 2.038 → 1.824.
TEST(ModulatingKernels, OptimisedKernelHasTheLowerNoiseGain) {
  for (int order : {2, 3}) {
    ModulatingKernelOptions minimal;
    minimal.order = order;
    minimal.noise_weights = Eigen::Vector2d(1.0, 0.5);
    const ModulatingKernels K0(2, 1.0, minimal);
    EXPECT_FALSE(K0.optimisation().has_value());
    ModulatingKernelOptions higher = minimal;
    higher.degree = 10;
    const ModulatingKernels K1(2, 1.0, higher);
    ASSERT_TRUE(K1.optimisation().has_value());
    for (int j = 0; j < 2; ++j) {
      EXPECT_LT(K1.noise_gain(j), K0.noise_gain(j)) << "order " << order << " j " << j;
    }
  }
}

TEST(ModulatingKernels, BadOptionsNameTheOption) {
  ModulatingKernelOptions o;
  o.order = 1;
  EXPECT_NE(message_of([&] { ModulatingKernels(2, 1.0, o); }).find("order 1 is below n = 2"),
            std::string::npos);
  o = {};
  o.degree = 2;
  EXPECT_NE(message_of([&] { ModulatingKernels(2, 1.0, o); }).find("degree 2"), std::string::npos);
  o = {};
  EXPECT_NE(message_of([&] { ModulatingKernels(2, -1.0, o); }).find("horizon"), std::string::npos);
  o.noise_weights = Eigen::Vector3d::Ones();
  EXPECT_NE(message_of([&] { ModulatingKernels(2, 1.0, o); }).find("noise_weights"),
            std::string::npos);
  o = {};
  o.degree = 6;
  const auto engine = [](const char* spec) {
    return EngineRegistry<Eigen::Dynamic>::global().create(spec,
                                                           modulating_kernel_solver_options());
  };
  EXPECT_EQ(message_of([&] { ModulatingKernels(2, 1.0, o, engine("newton")); }),
            "modulating kernel: engine 'newton' solves square systems only; use ceres or nlopt");
  // At the minimal degree there is nothing to optimise: any engine is accepted and unused.
  o.degree = 0;
  EXPECT_EQ(ModulatingKernels(2, 1.0, o, engine("newton")).engine(), "newton");
}

// The design engine is an object like every other engine (here NLopt's, by its spec, and
// Ceres' by default): both reach the same noise-optimal kernel.
TEST(ModulatingKernels, TheDesignEngineIsAnObject) {
  ModulatingKernelOptions o;
  o.degree = 8;
  o.noise_weights = Eigen::Vector2d(1.0, 2.0);
  const ModulatingKernels ceres(2, 1.0, o);
  const ModulatingKernels nlopt(
      2, 1.0, o,
      EngineRegistry<Eigen::Dynamic>::global().create("nlopt", modulating_kernel_solver_options()));
  EXPECT_EQ(ceres.engine(), "ceres");
  EXPECT_EQ(nlopt.engine(), "nlopt");
  ASSERT_TRUE(ceres.optimisation().has_value());
  ASSERT_TRUE(nlopt.optimisation().has_value());
  for (int j = 0; j < 2; ++j) {
    EXPECT_NEAR(nlopt.noise_gain(j), ceres.noise_gain(j), 1e-6 * ceres.noise_gain(j)) << j;
    for (const double s : {0.1, 0.5, 0.9}) {
      EXPECT_NEAR(nlopt.value(j, 0, s), ceres.value(j, 0, s), 1e-6) << j << " " << s;
    }
  }
}

// The chain y''' = 0 on a quadratic: the FIR (Simpson) reconstructs y, y', y'' one horizon in.
TEST(ModulatingFunctionObserver, ExactOnAQuadraticThroughTheFir) {
  const double delta = 1e-3;
  Measurements data;
  const Eigen::Index K = 1201;
  data.t = Eigen::VectorXd::LinSpaced(K, 0.0, (K - 1) * delta);
  data.y.resize(1, K);
  data.u.resize(0, K);
  data.x.resize(3, K);
  for (Eigen::Index k = 0; k < K; ++k) {
    const double t = data.t[k];
    data.y(0, k) = 1.0 - 2.0 * t + 0.7 * t * t;
    data.x.col(k) << data.y(0, k), -2.0 + 1.4 * t, 1.4;
  }
  ModulatingFunctionObserver<ChainForm<3>> observer(ChainForm<3>{}, options(delta, 0.5, 3));
  EXPECT_EQ(observer.info().window, 501);
  EXPECT_LT(relative_error_from(observer, data, 500), 1e-9);  // measured 2.1e-10
}

// The LTI example, noise-free at δ = 10 ms: exact to quadrature one horizon in.
TEST(ModulatingFunctionObserver, LtiExactOneHorizonAfterStart) {
  const Measurements data =
      simulate_continuous(LtiOutputInjection{}, Eigen::Vector2d(2.0, 0.0), 0.01, 6.0);
  for (Quadrature q : {Quadrature::kSimpson, Quadrature::kTrapezoid}) {
    ModulatingOptions o = options(0.01, 1.0);
    o.quadrature = q;
    ModulatingFunctionObserver<LtiInjectionForm> observer(LtiInjectionForm{}, o);
    int failures = 0;
    const double rel = relative_error_from(observer, data, observer.info().window - 1, &failures);
    EXPECT_EQ(failures, 0);
    // Simpson: measured 2e-9 (the plant's own RK4 error); the trapezoid rule's O(δ²) is 4e-5.
    EXPECT_LT(rel, q == Quadrature::kSimpson ? 1e-6 : 1e-3);
  }
}

TEST(ModulatingFunctionObserver, PendulumExactOneHorizonAfterStart) {
  const Measurements data =
      simulate_continuous(PendulumTimeVaryingFriction{}, Eigen::Vector2d(1.0, 0.0), 0.01, 6.0);
  ModulatingFunctionObserver<PendulumForm> observer(PendulumForm{}, options(0.01, 1.0));
  EXPECT_LT(relative_error_from(observer, data, observer.info().window - 1), 1e-6);
}

// Theorem 1: with |d| ≤ a_max/l the canonical error stays within the kernel's L1 gain times
// the level — and the bound is not vacuous (within a factor 20 of the error).
TEST(ModulatingFunctionObserver, DisturbedPendulumStaysWithinTheBound) {
  PendulumTimeVaryingFriction model;
  model.p.a_max = 0.5;
  const Measurements data = simulate_continuous(model, Eigen::Vector2d(1.0, 0.0), 0.01, 8.0);
  PendulumForm form{model.p};
  ModulatingOptions o = options(0.01, 1.0);
  o.disturbance_gains = Eigen::Vector2d(1.0, 0.0);
  o.disturbance_level = form.disturbance_level();
  ModulatingFunctionObserver<PendulumForm> observer(form, o);
  double worst = 0.0;
  for (Eigen::Index k = 0; k < data.steps(); ++k) {
    observer.step(k, data.t[k], data.y.col(k), data.u.col(k));
    if (k < observer.info().window - 1) continue;
    const Eigen::Vector2d error =
        observer.coordinates_at(data.x.col(k), data.t[k]) - Eigen::VectorXd(observer.eta());
    for (int j = 0; j < 2; ++j) {
      EXPECT_LE(std::abs(error[j]), observer.disturbance_bound()[j] * (1 + 1e-6) + 1e-8);
    }
    worst = std::max(worst, error.norm());
  }
  EXPECT_GT(worst, observer.disturbance_bound().norm() / 20.0);
}

// σ = 0.01 at δ = 10 ms: backward differences amplify the noise by √2/δ; the observer integrates.
TEST(ModulatingFunctionObserver, BeatsFiniteDifferencesUnderNoise) {
  const Measurements data =
      simulate_continuous(LtiOutputInjection{}, Eigen::Vector2d(2.0, 0.0), 0.01, 12.0, 0.01);
  ModulatingOptions o = options(0.01, 1.0);
  o.kernel.degree = 6;
  o.kernel.noise_weights = Eigen::Vector2d(1.0, 0.5);
  ModulatingFunctionObserver<LtiInjectionForm> observer(LtiInjectionForm{}, o);
  FiniteDifferenceObserver differences({.states = 2, .sample_time = 0.01});
  const double mf = derivative_rms(observer, data, 200);
  const double fd = derivative_rms(differences, data, 200);
  // The issue asks for 5×; measured 540× (mf 2.7e-3): 100× catches a regression.
  EXPECT_LT(100.0 * mf, fd) << "modulating " << mf << ", finite differences " << fd;
}

// Outputs every 0.1 s (10 grid steps), the predictor between: converges, noise-free.
TEST(ModulatingFunctionObserver, SampledDataConverges) {
  const Measurements data =
      simulate_continuous(LtiOutputInjection{}, Eigen::Vector2d(2.0, 0.0), 0.01, 12.0);
  ModulatingOptions o = options(0.01, 1.0);
  o.sample_period = 0.1;
  ModulatingFunctionObserver<LtiInjectionForm> observer(LtiInjectionForm{}, o);
  EXPECT_LT(relative_error_from(observer, data, 1000), 1e-6);
}

// A sample missing at a measurement time: the predictor bridges it, no failure, convergence.
TEST(ModulatingFunctionObserver, SampledDataBridgesAMissingSample) {
  Measurements data =
      simulate_continuous(LtiOutputInjection{}, Eigen::Vector2d(2.0, 0.0), 0.01, 12.0);
  data.y(0, 500) = std::nan("");  // t = 5 s, a measurement time (every 10th sample)
  ModulatingOptions o = options(0.01, 1.0);
  o.sample_period = 0.1;
  ModulatingFunctionObserver<LtiInjectionForm> observer(LtiInjectionForm{}, o);
  int failures = 0;
  for (Eigen::Index k = 0; k < data.steps(); ++k) {
    const ObserverStep& s = observer.step(k, data.t[k], data.y.col(k), data.u.col(k));
    failures += s.failure.empty() ? 0 : 1;
    if (k == 500) {
      EXPECT_TRUE(s.measurement_missing);
      EXPECT_TRUE(s.ready);  // the window holds predicted outputs, still valid
    }
  }
  EXPECT_EQ(failures, 0);
  const Eigen::Index K = data.steps() - 1;
  EXPECT_LT(
      (observer.coordinates_at(data.x.col(K), data.t[K]) - Eigen::VectorXd(observer.eta())).norm(),
      1e-6);
}

// A time jump far beyond a horizon (recorded data: t jumps from 6 s to 1e6 s): FIR mode skips
// the missing grid times at once and recovers exactly one horizon later; sampled-data mode
// restarts the predictor there. Each sample's work is independent of the gap (1e8 grid times
// would take minutes one by one).
TEST(ModulatingFunctionObserver, ATimeJumpIsSkippedAtOnceAndRecovers) {
  const Measurements data =
      simulate_continuous(LtiOutputInjection{}, Eigen::Vector2d(2.0, 0.0), 0.01, 12.0);
  for (const double period : {0.0, 0.1}) {
    ModulatingOptions o = options(0.01, 1.0);
    o.sample_period = period;
    ModulatingFunctionObserver<LtiInjectionForm> observer(LtiInjectionForm{}, o);
    // The second half of the data, shifted by 1e6 s (LTI: the dynamics do not depend on t).
    const Eigen::Index half = data.steps() / 2;
    bool jumped_missing = false, ready_again = false;
    for (Eigen::Index k = 0; k < data.steps(); ++k) {
      const double t = data.t[k] + (k >= half ? 1e6 : 0.0);
      const ObserverStep& s = observer.step(k, t, data.y.col(k), data.u.col(k));
      EXPECT_TRUE(s.failure.empty()) << s.failure_message;
      if (k == half) jumped_missing = s.measurement_missing && !s.ready;
      if (k > half + 150) ready_again = ready_again || s.ready;
    }
    EXPECT_TRUE(jumped_missing) << "period " << period;
    EXPECT_TRUE(ready_again) << "period " << period;
    const Eigen::Index K = data.steps() - 1;
    EXPECT_LT(
        (observer.coordinates_at(data.x.col(K), data.t[K] + 1e6) - Eigen::VectorXd(observer.eta()))
            .norm(),
        1e-6)
        << "period " << period;
  }
}

// n = 1: y' = v with v = u (a_0 = 0): η_0 = y, in FIR and in sampled-data mode (the predictor
// ŷ' = b_0 v integrates u exactly).
TEST(ModulatingFunctionObserver, FirstOrderChainInBothModes) {
  const double delta = 0.01;
  Measurements data;
  const Eigen::Index K = 400;
  data.t = Eigen::VectorXd::LinSpaced(K, 0.0, static_cast<double>(K - 1) * delta);
  data.y.resize(1, K);
  data.u = Eigen::MatrixXd::Constant(1, K, 2.0);
  data.x.resize(1, K);
  for (Eigen::Index k = 0; k < K; ++k) data.x(0, k) = data.y(0, k) = 3.0 + 2.0 * data.t[k];
  for (double period : {0.0, 0.2}) {
    ModulatingOptions o = options(delta, 0.5, 1);
    o.sample_period = period;
    ModulatingFunctionObserver<ChainForm<1>> observer(ChainForm<1>{}, o);
    EXPECT_LT(relative_error_from(observer, data, 100), 1e-9) << period;
  }
}

TEST(ModulatingFunctionObserver, RepeatedOrDecreasingTimesAreRefused) {
  ModulatingFunctionObserver<LtiInjectionForm> observer(LtiInjectionForm{}, options(0.01, 1.0));
  const Eigen::VectorXd y = Eigen::VectorXd::Ones(1), u(0);
  EXPECT_TRUE(observer.step(0, 0.0, y, u).failure.empty());
  EXPECT_TRUE(observer.step(1, 0.01, y, u).failure.empty());
  EXPECT_EQ(observer.step(2, 0.01, y, u).failure, "non_uniform");
  EXPECT_EQ(observer.step(3, 0.01 + 1e-9, y, u).failure, "non_uniform");  // same grid point
  EXPECT_EQ(observer.step(4, 0.005, y, u).failure, "non_uniform");
  EXPECT_FALSE(observer.step(4, 0.005, y, u).ready);
  EXPECT_TRUE(observer.step(5, 0.02, y, u).failure.empty());  // back on the grid
  EXPECT_EQ(observer.step(6, std::nan(""), y, u).failure, "non_finite");
}

// A first time too large for δ is refused before it can anchor the grid: the next sample starts.
TEST(ModulatingFunctionObserver, AHugeFirstTimeDoesNotAnchorTheGrid) {
  ModulatingFunctionObserver<LtiInjectionForm> observer(LtiInjectionForm{}, options(0.01, 1.0));
  const Eigen::VectorXd y = Eigen::VectorXd::Ones(1), u(0);
  EXPECT_EQ(observer.step(0, 1e300, y, u).failure, "non_uniform");
  EXPECT_TRUE(observer.step(1, 0.0, y, u).failure.empty());
  EXPECT_TRUE(observer.step(2, 0.01, y, u).failure.empty());
}

// Absolute (epoch) times carry their decimal rounding: still on the grid.
TEST(ModulatingFunctionObserver, AbsoluteTimesStayOnTheGrid) {
  ModulatingFunctionObserver<LtiInjectionForm> observer(LtiInjectionForm{}, options(0.01, 0.1));
  const Eigen::VectorXd y = Eigen::VectorXd::Ones(1), u(0);
  for (long k = 0; k < 30; ++k) {
    const double t = std::stod("1700000000." + std::to_string(100 + k).substr(1));  // ….00, ….01
    EXPECT_TRUE(observer.step(k, t, y, u).failure.empty()) << k;
  }
  EXPECT_TRUE(observer.step(30, 1700000000.30, y, u).ready);
}

// Resampling: samples every 15 ms onto a 10 ms grid are interpolated (short spans), a long gap
// leaves its grid points missing (the window refills).
TEST(ModulatingFunctionObserver, ResamplingBridgesShortSpansNotGaps) {
  const Measurements fine =
      simulate_continuous(LtiOutputInjection{}, Eigen::Vector2d(2.0, 0.0), 0.005, 8.0);
  ModulatingOptions o = options(0.01, 1.0);
  o.resample = true;
  o.quadrature = Quadrature::kTrapezoid;
  ModulatingFunctionObserver<LtiInjectionForm> observer(LtiInjectionForm{}, o);
  double worst = 0.0;
  long k = 0;
  for (Eigen::Index i = 0; i < fine.steps(); i += 3, ++k) {  // every 15 ms
    const ObserverStep& s = observer.step(k, fine.t[i], fine.y.col(i), fine.u.col(i));
    EXPECT_TRUE(s.failure.empty()) << s.failure_message;
    if (fine.t[i] > 1.5 && fine.t[i] < 5.0) {
      EXPECT_TRUE(s.ready) << fine.t[i];
      worst = std::max(worst, (s.estimate - fine.x.col(i)).norm());
    }
  }
  // Linear interpolation of y between samples 15 ms apart (error ~ y''·h²/8 ≈ 6e-5 in y, a
  // bias the kernels' second derivatives amplify): measured 3.5e-3 in x, against 1e-9 on-grid.
  EXPECT_LT(worst, 1e-2);
  // A 0.5 s gap (more than 4 δ): its grid points are missing, the window refills for 1 s.
  const double t_gap = fine.t[fine.steps() - 1] + 0.5;
  const Eigen::VectorXd y = fine.y.col(fine.steps() - 1);
  EXPECT_FALSE(observer.step(k, t_gap, y, fine.u.col(0)).ready);
}

TEST(ModulatingFunctionObserver, NanSampleInvalidatesTheWindowUntilRefilled) {
  Measurements data =
      simulate_continuous(LtiOutputInjection{}, Eigen::Vector2d(2.0, 0.0), 0.01, 4.0);
  data.y(0, 200) = std::nan("");
  ModulatingFunctionObserver<LtiInjectionForm> observer(LtiInjectionForm{}, options(0.01, 1.0));
  Eigen::VectorXd kept;
  for (Eigen::Index k = 0; k < data.steps(); ++k) {
    const ObserverStep& s = observer.step(k, data.t[k], data.y.col(k), data.u.col(k));
    if (k == 199) kept = s.estimate;
    if (k == 200) {
      EXPECT_TRUE(s.measurement_missing);
      EXPECT_EQ(s.estimate, kept);
    }
    if (k >= 200 && k < 301) {
      EXPECT_FALSE(s.ready) << k;
    }
    if (k == 301) {
      EXPECT_TRUE(s.ready);
      EXPECT_LT((s.estimate - data.x.col(k)).norm(), 1e-6);
    }
  }
}

TEST(ModulatingFunctionObserver, NonUniformTimesAreRefusedOrResampled) {
  const Measurements data =
      simulate_continuous(LtiOutputInjection{}, Eigen::Vector2d(2.0, 0.0), 0.005, 4.0);
  // Every other sample, with one jittered time: a 10 ms grid that one sample leaves.
  Measurements sparse;
  const Eigen::Index K = data.steps() / 2;
  sparse.t.resize(K);
  sparse.y.resize(1, K);
  sparse.u.resize(0, K);
  sparse.x.resize(2, K);
  for (Eigen::Index k = 0; k < K; ++k) {
    const Eigen::Index from = 2 * k + (k == 150 ? 1 : 0);
    sparse.t[k] = data.t[from];
    sparse.y(0, k) = data.y(0, from);
    sparse.x.col(k) = data.x.col(from);
  }
  ModulatingFunctionObserver<LtiInjectionForm> strict(LtiInjectionForm{}, options(0.01, 1.0));
  Eigen::VectorXd before;
  for (Eigen::Index k = 0; k < K; ++k) {
    const ObserverStep& s = strict.step(k, sparse.t[k], sparse.y.col(k), sparse.u.col(k));
    if (k == 149) before = s.estimate;
    if (k == 150) {
      EXPECT_EQ(s.failure, "non_uniform");
      EXPECT_NE(s.failure_message.find("resample"), std::string::npos);
      EXPECT_EQ(s.estimate, before);
    }
  }
  ModulatingOptions o = options(0.01, 1.0);
  o.resample = true;
  ModulatingFunctionObserver<LtiInjectionForm> resampling(LtiInjectionForm{}, o);
  for (Eigen::Index k = 0; k < K; ++k) {
    const ObserverStep& s = resampling.step(k, sparse.t[k], sparse.y.col(k), sparse.u.col(k));
    EXPECT_TRUE(s.failure.empty()) << k << ": " << s.failure_message;
    // One linearly interpolated sample in the window costs accuracy until it leaves it.
    if (k > 260) {
      EXPECT_LT((s.estimate - sparse.x.col(k)).norm(), 1e-6) << k;
    }
  }
}

TEST(ModulatingFunctionObserver, BadOptionsNameTheOption) {
  const auto make = [](ModulatingOptions o) {
    ModulatingFunctionObserver<LtiInjectionForm>(LtiInjectionForm{}, o);
  };
  EXPECT_NE(message_of([&] {
              make(options(0.01, 0.03));
            }).find("ModulatingOptions::horizon must span at least 4 intervals"),
            std::string::npos);
  EXPECT_NE(message_of([&] {
              make(options(0.01, 0.105));
            }).find("ModulatingOptions::horizon must be a multiple of sample_time 0.01"),
            std::string::npos);
  EXPECT_NE(message_of([&] { make(options(0.01, 0.05)); }).find("for Simpson quadrature"),
            std::string::npos);
  EXPECT_NE(message_of([&] {
              make(options(0.0, 1.0));
            }).find("ModulatingOptions::sample_time must be finite and > 0 (got 0)"),
            std::string::npos);
  ModulatingOptions o = options(0.01, 1.0);
  o.sample_period = 0.015;
  EXPECT_NE(message_of([&] { make(o); }).find("ModulatingOptions::sample_period must be"),
            std::string::npos);
  o = options(0.01, 1.0);
  o.kernel.order = 1;
  EXPECT_NE(message_of([&] { make(o); }).find("order 1 is below n = 2"), std::string::npos);
  o = options(0.01, 1.0);
  o.disturbance_gains = Eigen::Vector3d::Ones();
  EXPECT_NE(
      message_of([&] { make(o); }).find("ModulatingOptions::disturbance_gains must have n = 2"),
      std::string::npos);
  EXPECT_NE(
      message_of([&] { make(options(0.01, 1.0, 3)); }).find("ModulatingOptions::initial_estimate"),
      std::string::npos);
}

// validate() alone, without a form: each bad field is named with the value given.
TEST(ModulatingOptions, ValidateNamesTheFieldAndValue) {
  ModulatingOptions good = options(0.01, 1.0);
  EXPECT_NO_THROW(good.validate());
  good.sample_period = 0.1;  // the optional fields, given and valid
  good.resample = true;
  good.resample_max_gap = 0.02;
  good.disturbance_gains = Eigen::Vector2d(1.0, 0.0);
  good.disturbance_level = 0.5;
  EXPECT_NO_THROW(good.validate());
  const struct {
    void (*spoil)(ModulatingOptions&);
    const char* field;
    const char* got;  // the value as the message shows it
  } cases[] = {
      {[](ModulatingOptions& o) { o.name.clear(); }, "name", "(got \"\")"},
      {[](ModulatingOptions& o) { o.initial_estimate = Eigen::Vector2d(0.0, std::nan("")); },
       "initial_estimate", "nan"},
      {[](ModulatingOptions& o) { o.initial_estimate.resize(0); }, "initial_estimate", "(got 0x1)"},
      {[](ModulatingOptions& o) { o.sample_time = -1.0; }, "sample_time", "(got -1)"},
      {[](ModulatingOptions& o) { o.horizon = std::nan(""); }, "horizon", "nan"},
      {[](ModulatingOptions& o) { o.horizon = 0.105; }, "horizon", "(got 0.105)"},
      {[](ModulatingOptions& o) { o.horizon = 0.03; }, "horizon", "(got 0.03: 3 intervals)"},
      {[](ModulatingOptions& o) { o.horizon = 0.05; }, "horizon", "(got 0.05: 5 intervals)"},
      {[](ModulatingOptions& o) { o.sample_period = 0.015; }, "sample_period", "(got 0.015)"},
      {[](ModulatingOptions& o) { o.sample_period = -0.1; }, "sample_period", "(got -0.1)"},
      {[](ModulatingOptions& o) { o.sample_period = std::numeric_limits<double>::infinity(); },
       "sample_period", "(got inf)"},
      {[](ModulatingOptions& o) { o.resample_max_gap = 0.005; }, "resample_max_gap", "(got 0.005)"},
      {[](ModulatingOptions& o) { o.disturbance_level = -1.0; }, "disturbance_level", "(got -1)"},
      {[](ModulatingOptions& o) {  // a level is checked without gains too (it was ignored)
         o.disturbance_gains.resize(0);
         o.disturbance_level = std::nan("");
       },
       "disturbance_level", "(got nan)"},
      {[](ModulatingOptions& o) { o.disturbance_gains = Eigen::Vector2d(1.0, std::nan("")); },
       "disturbance_gains", "nan"},
  };
  for (const auto& c : cases) {
    ModulatingOptions o = good;
    c.spoil(o);
    const std::string message = message_of([&] { o.validate(); });
    EXPECT_NE(message.find(std::string("ModulatingOptions::") + c.field + " must "),
              std::string::npos)
        << message;
    EXPECT_NE(message.find(c.got), std::string::npos) << c.field << ": " << message;
  }
}

// The size of x̂(0) needs the form: the constructor refuses it after validate().
TEST(ModulatingFunctionObserver, InitialEstimateOfTheWrongSizeIsRefused) {
  EXPECT_EQ(message_of([] {
              ModulatingFunctionObserver<LtiInjectionForm>(LtiInjectionForm{},
                                                           options(0.01, 1.0, 3));
            }),
            "ModulatingOptions::initial_estimate must have 2 entries (got 3)");
  EXPECT_EQ(message_of([] {
              ModulatingFunctionObserver<ChainForm<3>>(ChainForm<3>{}, options(0.01, 1.0));
            }),
            "ModulatingOptions::initial_estimate must have 3 entries (got 2)");
}

TEST(FiniteDifferenceObserver, DifferencesAPolynomialExactly) {
  FiniteDifferenceObserver fd({.states = 3, .sample_time = 0.1});
  Eigen::VectorXd y(1), u(0);
  for (long k = 0; k < 5; ++k) {
    y[0] = 0.5 * std::pow(0.1 * static_cast<double>(k), 2);  // y = t²/2: ∇y/δ = t − δ/2, ∇²y/δ² = 1
    const ObserverStep& s = fd.step(k, 0.1 * static_cast<double>(k), y, u);
    EXPECT_EQ(s.ready, k >= 2);
    if (k >= 2) {
      EXPECT_NEAR(s.estimate[1], 0.1 * static_cast<double>(k) - 0.05, 1e-12);
      EXPECT_NEAR(s.estimate[2], 1.0, 1e-9);
    }
  }
  EXPECT_EQ(fd.name(), "finite_difference");
  const auto refusal = [](FiniteDifferenceOptions o) {
    try {
      FiniteDifferenceObserver refused(std::move(o));
    } catch (const InvalidInput& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(refusal({.states = 0, .sample_time = 0.1}),
            "FiniteDifferenceOptions::states must be >= 1 (got 0)");
  EXPECT_EQ(refusal({.states = 2, .sample_time = -0.1}),
            "FiniteDifferenceOptions::sample_time must be finite and > 0 (got -0.1)");
  EXPECT_EQ(refusal({.name = "", .states = 2, .sample_time = 0.1}),
            "FiniteDifferenceOptions::name must not be empty (got \"\")");
}

// The differences divide by δ: a sample off the grid t_0 + k δ is refused (not differenced
// across the wrong span), and a skipped k restarts them like a missing sample.
TEST(FiniteDifferenceObserver, SamplesOffTheGridOrSkippedRestartTheDifferences) {
  FiniteDifferenceObserver fd({.states = 2, .sample_time = 0.1});
  const Eigen::VectorXd u(0);
  const auto y = [](double t) { return Eigen::VectorXd::Constant(1, 3.0 * t); };  // y' = 3
  // Recorded times from t_0 = 5: the grid starts at the first sample.
  EXPECT_FALSE(fd.step(0, 5.0, y(5.0), u).ready);
  EXPECT_NEAR(fd.step(1, 5.1, y(5.1), u).estimate[1], 3.0, 1e-9);
  const ObserverStep& off = fd.step(2, 5.25, y(5.25), u);
  EXPECT_EQ(off.failure, "non_uniform");
  EXPECT_NE(off.failure_message.find("finite_difference: sample k = 2 at t = 5.25"),
            std::string::npos)
      << off.failure_message;
  EXPECT_FALSE(off.ready);
  EXPECT_FALSE(fd.step(3, 5.3, y(5.3), u).ready);  // restarted: one sample so far
  EXPECT_TRUE(fd.step(4, 5.4, y(5.4), u).ready);
  EXPECT_FALSE(fd.step(6, 5.6, y(5.6), u).ready);  // k = 5 never came: restarted
  EXPECT_NEAR(fd.step(7, 5.7, y(5.7), u).estimate[1], 3.0, 1e-9);
  EXPECT_EQ(fd.step(8, std::nan(""), y(5.8), u).failure, "non_finite");
}

}  // namespace
}  // namespace nlobs
