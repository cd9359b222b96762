// The fixed-size path allocates nothing on the heap during a solve: this binary replaces the
// global operator new to count allocations around each solve.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>
#include <vector>

#include "nlobs/models/embedded_forms.hpp"
#include "nlobs/models/modified_chua.hpp"
#include "nlobs/models/systems.hpp"
#include "nlobs/observers/baselines/finite_difference_observer.hpp"
#include "nlobs/observers/core/simulation.hpp"
#include "nlobs/observers/high_gain/high_gain_observer.hpp"
#include "nlobs/observers/high_gain/taylor_observability_map.hpp"
#include "nlobs/observers/mhe/mhe_estimator.hpp"
#include "nlobs/observers/modulating/modulating_function_observer.hpp"
#include "nlobs/observers/mvt/mvt_observer.hpp"
#include "nlobs/observers/pi/pi_bank.hpp"
#include "nlobs/observers/window/window_estimator.hpp"
#include "nlobs/registry/problem_sets/chua_window_set.hpp"
#include "nlobs/solvers/ceres_engine.hpp"
#include "nlobs/solvers/engine_registry.hpp"
#include "nlobs/solvers/solvers.hpp"

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

void* operator new(std::size_t size) {
  ++g_allocations;
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) {
  return operator new(size);
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}

namespace nlobs {
namespace {

using ChuaWindow = reference::ChuaWindowCase;

long allocations_during_solve(Engine<3>& engine, const FixedPointProblem<3>& problem) {
  Vector<3> x(5.0, 10.0, -5.0);
  engine.solve(problem, x);  // warm-up (nothing should be lazily allocated either)
  x = Vector<3>(5.0, 10.0, -5.0);
  const long before = g_allocations.load();
  const Summary s = engine.solve(problem, x);
  const long after = g_allocations.load();
  EXPECT_TRUE(s.converged()) << s.full_report();
  return after - before;
}

TEST(Allocations, CounterSeesAllocations) {
  const long before = g_allocations.load();
  void* volatile p = ::operator new(64);  // the counter itself works
  ::operator delete(p);
  std::vector<double> v(100);
  v[7] = 1.0;
  EXPECT_GE(g_allocations.load() - before, 1);
}

TEST(Allocations, FixedSizeSolvesAllocateNothing) {
  ChuaWindow cw;
  SolverOptions o;
  o.stop.step_tolerance = 1e-10;
  o.stop.residual_tolerance = 1e-12;
  PicardEngine<3> picard(o);
  AitkenEngine<3> aitken(o);
  SteffensenEngine<3> steffensen(o);
  AndersonEngine<3> anderson({.depth = 3}, o);
  NewtonEngine<3> newton({}, o);
  NewtonEngine<3> newton_ls({.line_search = true}, o);
  CeresEngine<3> tiny({.backend = CeresOptions::Backend::kTinySolver}, o);
  DoglegEngine<3> dogleg({}, o);
  // Its residual and Jacobian workspaces have m rows: sized by the warm-up, reused after.
  LevenbergMarquardtEngine<3> lm({}, o);
  BroydenEngine<3> broyden({}, o);
  for (Engine<3>* e :
       std::initializer_list<Engine<3>*>{&picard, &aitken, &steffensen, &anderson, &newton,
                                         &newton_ls, &tiny, &dogleg, &lm, &broyden}) {
    EXPECT_EQ(allocations_during_solve(*e, cw.problem), 0) << e->name();
  }
  // In a box (wide enough to hold the run): the projection and the box allocate nothing either.
  const BoxBounds box{Eigen::Vector3d::Constant(-100.0), Eigen::Vector3d::Constant(100.0)};
  for (Engine<3>* e :
       std::initializer_list<Engine<3>*>{&newton, &newton_ls, &dogleg, &lm, &broyden}) {
    e->set_bounds(box);
    EXPECT_EQ(allocations_during_solve(*e, cw.problem), 0) << e->name() << " in a box";
  }
}

TEST(Allocations, FiniteDifferenceAndMatrixPreconditionerAllocateNothing) {
  ChuaWindow cw;
  const auto f = [&cw](const Vector<3>& w, Vector<3>& r) {
    cw.window->map_into(w, r);
    r = cw.window->outputs() - r;
  };
  const auto by_fd = to_fixed_point(RootProblem<3>::from_map(f));
  Matrix<3, 3> psi = Matrix<3, 3>::Identity();
  const auto by_matrix = to_fixed_point<3>(RootProblem<3>::from_map(f), psi);
  SolverOptions o;
  o.stop.step_tolerance = 1e-10;
  NewtonEngine<3> newton({}, o);
  SteffensenEngine<3> steffensen(o);
  EXPECT_EQ(allocations_during_solve(newton, by_fd), 0);
  EXPECT_EQ(allocations_during_solve(steffensen, by_matrix), 0);
}

// A PI bank's step (RK4 over the interval, every stage evaluated 4 × substeps times) works in
// buffers sized at construction.
TEST(Allocations, PiBankStepAllocatesNothing) {
  PiBank bank(1, 1);
  const auto y = bank.output(0), u = bank.input(0);
  const auto x2 = bank.add_pi("x2", {.measured = y, .gains = {6, 25}});
  const auto x3 = bank.add_signal(
      "x3", [=](const PiBank::Values& v) { return 1e4 * v[u] / (1.63 - v[x2.rate]); });
  const auto f = bank.add_pi("f", {.measured = x3,
                                   .a = -1.0,
                                   .b = [=](const PiBank::Values& v) { return -50 * v[u]; },
                                   .gains = {49, 700}});
  PiBankObserver observer(
      bank, {.name = "pi", .estimate = {y, x2.eta, x3, f.eta}, .sample_time = 1e-3, .substeps = 2});
  Eigen::VectorXd yk(1), uk = Eigen::VectorXd::Ones(1);
  yk[0] = -700.0;
  observer.step(0, 0.0, yk, uk);
  const long before = g_allocations.load();
  for (long k = 1; k < 100; ++k) {
    yk[0] = -700.0 - 1e-3 * static_cast<double>(k);
    observer.step(k, 1e-3 * static_cast<double>(k), yk, uk);
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
}

// An MVT step with the per-row β search (secant, grid, TOMS 748, Brent) and RK4 on std::array
// states: fixed-size work only, with ê far from zero so every β problem is solved.
// A window-estimator step on the paper's Chua window, noisy data (so solves take iterations
// and Ψ = newton refreshes now and then): nothing allocated, whatever Ψ and engine.
TEST(Allocations, WindowEstimatorStepAllocatesNothing) {
  using Chua = Discretized<ModifiedChua>;
  SimulationOptions so;
  so.steps = 200;
  so.sample_time = 0.05;
  so.noise_std = 0.01;
  const Measurements data =
      simulate(paper_modified_chua(), Eigen::Vector3d(1, 2.1428, -0.1648), so);
  for (const char* engine : {"picard", "steffensen", "anderson", "newton"}) {
    for (WindowGain gain : {WindowGain::kIdentity, WindowGain::kNewton}) {
      SolverOptions solver;
      solver.stop.step_tolerance = 1e-8;
      solver.stop.residual_tolerance = 1e-8;
      WindowEstimatorOptions options;
      options.initial_estimate = Eigen::Vector3d(5.0, 10.0, -5.0);
      options.gain = gain;
      WindowEstimator<Chua> estimator(paper_modified_chua(), options,
                                      EngineRegistry<3>::global().create(engine, solver));
      const Eigen::VectorXd no_input(0);
      Eigen::VectorXd y(1);
      for (long k = 0; k < 10; ++k) {  // the first windows: Ψ chosen, workspaces sized
        y = data.y.col(k);
        estimator.step(k, data.t[k], y, no_input);
      }
      long solves = 0;
      const long before = g_allocations.load();
      for (long k = 10; k < data.steps(); ++k) {
        y = data.y.col(k);
        solves += estimator.step(k, data.t[k], y, no_input).summary.has_value();
      }
      EXPECT_EQ(g_allocations.load() - before, 0) << engine << " psi " << to_string(gain);
      EXPECT_EQ(solves, data.steps() - 10);
    }
  }
}

// The moving-horizon estimator on the same noisy Chua data, bounded and not, converged and with one
// real-time iteration: once the horizon is full, a step (rotate, arrival-cost update, Gauss–Newton
// with its block-tridiagonal solves and line search) allocates nothing.
TEST(Allocations, MheStepAllocatesNothing) {
  using Chua = Discretized<ModifiedChua>;
  SimulationOptions so;
  so.steps = 200;
  so.noise_std = 0.01;
  const Measurements data =
      simulate(paper_modified_chua(), Eigen::Vector3d(1, 2.1428, -0.1648), so);
  for (const bool rti : {false, true}) {
    for (const bool bounded : {false, true}) {
      MheOptions o;
      o.initial_estimate = Eigen::Vector3d(5.0, 10.0, -5.0);
      o.initial_covariance = 10.0 * Eigen::Matrix3d::Identity();
      o.horizon = 12;
      o.real_time_iteration = rti;
      // x2 ≥ −0.5 is active: the true x2 reaches −0.96
      if (bounded) o.lower_bounds = Eigen::Vector3d(-40.0, -0.5, -40.0);
      MheEstimator<Chua> mhe(paper_modified_chua(), o);
      const Eigen::VectorXd no_input(0);
      Eigen::VectorXd y(1);
      for (long k = 0; k < 20; ++k) {
        y = data.y.col(k);
        mhe.step(k, data.t[k], y, no_input);
      }
      long iterations = 0;
      const long before = g_allocations.load();
      for (long k = 20; k < data.steps(); ++k) {
        y = data.y.col(k);
        iterations += mhe.step(k, data.t[k], y, no_input).summary->iterations;
      }
      EXPECT_EQ(g_allocations.load() - before, 0) << "rti " << rti << " bounded " << bounded;
      EXPECT_GE(iterations, data.steps() - 20);
    }
  }
}

TEST(Allocations, MvtStepWithPerRowBetaAllocatesNothing) {
  MvtOptions o;
  o.sample_time = 1e-3;
  o.initial_estimate = Eigen::Vector4d(-1, -2, -0.5, -1);
  o.initial_error_estimate = Eigen::Vector4d(4, 5, 3.5, 3);
  MvtObserver<FlexibleJointRobot> observer(FlexibleJointRobot{}, o);
  Eigen::VectorXd yk = Eigen::Vector3d(3, 3, 3), uk = Eigen::VectorXd::Zero(1);
  observer.step(0, 0.0, yk, uk);
  const long before = g_allocations.load();
  for (long k = 1; k < 100; ++k) {
    yk += Eigen::Vector3d::Constant(1e-3);
    uk[0] = std::sin(1e-3 * static_cast<double>(k));
    observer.step(k, 1e-3 * static_cast<double>(k), yk, uk);
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_GT(observer.ehat().norm(), 1e-3);  // the β problems were real ones
}

// A high-gain step with an explicit map, α and inverse (the oscillator of [HG-EMB23]) on RK4:
// the embedded state is dynamic-size but allocated once, so the step allocates nothing.
TEST(Allocations, HighGainStepWithExplicitFormsAllocatesNothing) {
  HighGainOptions o;
  o.initial_estimate = Eigen::Vector2d(-0.3, 0.0);
  o.design.map = std::make_shared<ExplicitObservabilityMap<OscillatorEmbedding>>();
  o.design.alpha = explicit_alpha<OscillatorEmbedding>();
  o.design.inverse = explicit_inverse<OscillatorEmbedding>();
  o.sample_time = 1e-2;
  o.theta = 0.3;
  o.saturation = SmoothSaturation{Eigen::MatrixXd::Identity(4, 4) * 0.2, 1.0, 2.0};
  HighGainObserver<OscillatorNonlinearOutput> observer(OscillatorNonlinearOutput{}, o);
  const Eigen::VectorXd none(0);
  Eigen::VectorXd yk = Eigen::VectorXd::Constant(1, -0.25);
  observer.step(0, 0.0, yk, none);
  observer.step(1, 1e-2, yk, none);
  const long before = g_allocations.load();
  for (long k = 2; k < 100; ++k) {
    yk[0] = -0.25 + 0.01 * std::sin(0.01 * static_cast<double>(k));
    observer.step(k, 1e-2 * static_cast<double>(k), yk, none);
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_GT(observer.zhat().norm(), 0.1);
}

// q_N, its Jacobian and L_f^N h with its gradient by Taylor mode (fvar lives on the stack) into
// outputs of the right size: no allocation, unlike the ADOL-C map whose drivers allocate.
TEST(Allocations, TaylorObservabilityMapAllocatesNothing) {
  const TaylorObservabilityMap<Lorenz, 4> map;
  Eigen::VectorXd x = Eigen::Vector3d(1.0, -2.0, 20.0), z(4), gradient(3);
  Eigen::MatrixXd dq(4, 3);
  double next = 0.0, sum = 0.0;
  const long before = g_allocations.load();
  for (int k = 0; k < 100; ++k) {
    x[0] += 0.01;
    EXPECT_TRUE(map.value(x, z));
    EXPECT_TRUE(map.jacobian(x, dq));
    EXPECT_TRUE(map.next(x, next, &gradient));
    sum += z[3] + dq(3, 2) + next + gradient[0];
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_TRUE(std::isfinite(sum));
  EXPECT_NE(dq(3, 2), 0.0);  // ∂(L_f^3 h)/∂x3 ≠ 0 off the x3 axis
}

// With that map a whole high-gain step without explicit forms — α = L_f^4 h along the
// prediction and x̂ by the Ceres projection (Lorenz, RK4) — allocates nothing either.
TEST(Allocations, HighGainStepWithTaylorMapAndProjectionAllocatesNothing) {
  HighGainOptions o;
  o.initial_estimate = Eigen::Vector3d(2.0, 3.0, 25.0);
  o.design.map = std::make_shared<TaylorObservabilityMap<Lorenz, 4>>();
  o.sample_time = 1e-3;
  o.theta = 0.02;
  HighGainObserver<Lorenz> observer(Lorenz{}, o);
  const Eigen::VectorXd none(0);
  Eigen::VectorXd yk = Eigen::VectorXd::Constant(1, 1.0);
  for (long k = 0; k < 5; ++k) observer.step(k, 1e-3 * static_cast<double>(k), yk, none);
  const Eigen::VectorXd z5 = observer.zhat();
  long failures = 0;
  const long before = g_allocations.load();
  for (long k = 5; k < 100; ++k) {
    yk[0] = 1.0 + 0.1 * std::sin(0.01 * static_cast<double>(k));
    failures += observer.step(k, 1e-3 * static_cast<double>(k), yk, none).failure.empty() ? 0 : 1;
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_EQ(failures, 0);
  EXPECT_GT((observer.zhat() - z5).norm(), 1e-3);
}

// The backward differences place each sample on their grid (UniformGrid) and difference it:
// nothing allocated on the way, the restart after a skipped grid point included.
TEST(Allocations, BackwardDifferenceStepAllocatesNothing) {
  FiniteDifferenceObserver fd({.states = 3, .sample_time = 0.01});
  Eigen::VectorXd y = Eigen::VectorXd::Zero(1), u(0);
  fd.step(0, 0.0, y, u);
  const long before = g_allocations.load();
  bool ready = false;
  for (long k = 1; k < 100; ++k) {
    const long m = k < 50 ? k : k + 1;  // grid point 50 never comes
    y[0] = std::sin(0.01 * static_cast<double>(m));
    ready = fd.step(k, 0.01 * static_cast<double>(m), y, u).ready;
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_TRUE(ready);
}

// A modulating-function step (FIR mode and sampled-data mode with the predictor): ring buffers
// and weights are allocated at construction.
TEST(Allocations, ModulatingFunctionStepAllocatesNothing) {
  for (double period : {0.0, 0.1}) {
    ModulatingOptions o;
    o.sample_time = 0.01;
    o.horizon = 0.5;
    o.sample_period = period;
    o.initial_estimate = Eigen::Vector2d::Zero();
    ModulatingFunctionObserver<PendulumForm> observer(PendulumForm{}, o);
    const Eigen::VectorXd none(0);
    Eigen::VectorXd yk(1);
    const long before = g_allocations.load();
    for (long k = 0; k < 200; ++k) {
      yk[0] = std::sin(0.01 * static_cast<double>(k));
      observer.step(k, 0.01 * static_cast<double>(k), yk, none);
    }
    EXPECT_EQ(g_allocations.load() - before, 0) << period;
    EXPECT_GT(Eigen::VectorXd(observer.eta()).norm(), 0.1);
  }
}

}  // namespace
}  // namespace nlobs
