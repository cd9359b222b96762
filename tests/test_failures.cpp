// Estimates that never lock onto a wrong answer, and failures that are never silent: the
// solver layer's usable() policy, window estimators on a user's model where Ψ = I does not
// contract, guesses at unobservable points, baselines that overflow, the harness's accounting,
// and the reference adapters' success.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "nlobs/models/discretization.hpp"
#include "nlobs/models/systems.hpp"
#include "nlobs/observers/baselines/baselines.hpp"
#include "nlobs/observers/core/simulation.hpp"
#include "nlobs/observers/window/window_estimator.hpp"
#include "nlobs/reference/kinsol_adapter.hpp"
#include "nlobs/reference/root_reference.hpp"
#include "nlobs/solvers/dynamic_size_engine.hpp"
#include "nlobs/solvers/engine_registry.hpp"
#include "nlobs/solvers/solvers.hpp"
#include "test_support.hpp"

namespace nlobs {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// ---------------------------------------------------------------------------------------------
// Summary::usable(): the one policy.

Summary summary_with(Status status, double residual, bool finite = true) {
  Summary s;
  s.status = status;
  s.residual_norm = residual;
  Eigen::Vector2d x(1.0, finite ? 2.0 : kNaN);
  s.record_answer(x, StopCriteria{});
  return s;
}

TEST(Usable, ConvergedFiniteIsUsable) {
  EXPECT_TRUE(summary_with(Status::kConverged, 1e-12).usable());
  EXPECT_TRUE(summary_with(Status::kConverged, 1e-12).unusable_reason().empty());
}

TEST(Usable, NonFinitePointIsNeverUsable) {
  const Summary s = summary_with(Status::kConverged, 1e-12, /*finite=*/false);
  EXPECT_FALSE(s.usable());
  EXPECT_NE(s.unusable_reason().find("not finite"), std::string::npos);
  EXPECT_FALSE(summary_with(Status::kConverged, std::numeric_limits<double>::infinity()).usable());
}

TEST(Usable, CutShortCountsOnlyWithASmallResidual) {
  for (Status cut : {Status::kMaxIterations, Status::kMaxEvaluations, Status::kStagnated,
                     Status::kRepeatedIterates}) {
    EXPECT_TRUE(summary_with(cut, 1e-9).usable()) << to_string(cut);
    const Summary big = summary_with(cut, 1.5e3);  // the traced case: stagnated at |F| 1.5e3
    EXPECT_FALSE(big.usable()) << to_string(cut);
    EXPECT_NE(big.unusable_reason().find("acceptance_tolerance"), std::string::npos);
    EXPECT_FALSE(summary_with(cut, kNaN).usable()) << "no residual known: " << to_string(cut);
  }
}

TEST(Usable, FailuresAreNeverUsable) {
  for (Status bad : {Status::kDiverged, Status::kNonFinite, Status::kSingularJacobian,
                     Status::kSolverFailure, Status::kInvalidInput, Status::kBlockedByBound}) {
    EXPECT_FALSE(summary_with(bad, 0.0).usable()) << to_string(bad);
  }
}

TEST(Usable, ConvergedByStepWithAResidualAboveItsToleranceIsNot) {
  Summary s;
  s.status = Status::kConverged;
  s.residual_norm = 1e-3;
  StopCriteria c;
  c.residual_tolerance = 1e-8;
  s.record_answer(Eigen::Vector2d(1.0, 2.0), c);
  EXPECT_FALSE(s.usable());
  EXPECT_NE(s.unusable_reason().find("converged by its step"), std::string::npos);
  // Within acceptance_tolerance (1e-6) a converged answer stands even above a tighter
  // residual_tolerance: such an answer is as good as a cut-short one that counts.
  s.residual_norm = 1e-7;
  EXPECT_TRUE(s.usable());
}

TEST(Usable, LeastSquaresCutShortIsNotJudgedByItsResidual) {
  Summary s;
  s.status = Status::kMaxIterations;
  s.residual_norm = 1e-9;
  s.record_answer(Eigen::Vector2d(1.0, 2.0), StopCriteria{}, /*minimised=*/true);
  EXPECT_FALSE(s.usable());
  s.status = Status::kConverged;
  s.residual_norm = 0.3;  // a least-squares point keeps a residual
  EXPECT_TRUE(s.usable());
}

TEST(Usable, AcceptanceToleranceIsValidated) {
  StopCriteria c;
  c.acceptance_tolerance = 0.0;
  EXPECT_THROW(validate(c), InvalidInput);
  c.acceptance_tolerance = kNaN;
  EXPECT_THROW(validate(c), InvalidInput);
  c.acceptance_tolerance = 1e-3;
  EXPECT_NO_THROW(validate(c));
}

// Every built-in engine records its answer; on G(x) = 2x + 1 (no contraction) the fixed-point
// engines' answers are not usable, whatever the status.
TEST(Usable, EveryEngineRecordsItsAnswer) {
  const auto expanding = FixedPointProblem<Dynamic>::with_autodiff(
      [](const auto& x) {
        using T = typename std::decay_t<decltype(x)>::Scalar;
        return Vector<Dynamic, T>(2.0 * x + Vector<Dynamic, T>::Ones(x.size()));
      },
      2);
  SolverOptions o;
  o.stop.max_iterations = 50;
  for (const char* spec :
       {"picard", "aitken", "steffensen", "anderson", "newton", "ceres", "nlopt:LD_SLSQP"}) {
    auto engine = EngineRegistry<Dynamic>::global().create(spec, o);
    Eigen::VectorXd x = Eigen::VectorXd::Constant(2, 0.5);
    const Summary s = engine->solve(expanding, x);
    EXPECT_TRUE(s.answer_recorded) << spec;
    EXPECT_EQ(s.usable(), x.allFinite() && (x.array() + 1.0).abs().maxCoeff() < 1e-6)
        << spec << ": " << s.brief_report();
  }
  // A Dynamic engine serving a fixed size (DynamicSizeEngine) hands its record on.
  DynamicSizeEngine<2> adapted(EngineRegistry<Dynamic>::global().create("picard", o));
  const auto expanding2 = FixedPointProblem<2>::from_map(
      [](const Vector<2>& x, Vector<2>& g) { g = 2.0 * x + Vector<2>::Ones(); });
  Vector<2> x2 = Vector<2>::Constant(0.5);
  const Summary s = adapted.solve(expanding2, x2);
  EXPECT_TRUE(s.answer_recorded);
  EXPECT_FALSE(s.usable()) << s.brief_report();
  EXPECT_TRUE(adapted.needs_contraction());
}

TEST(Usable, AnEngineThatRecordsNothingIsUsableOnlyWhenConverged) {
  Summary s;  // what a user's engine returns if it fills only the status
  s.status = Status::kMaxIterations;
  s.record_answer(Eigen::Vector2d(1.0, 2.0), StopCriteria{});  // done by the observer for it
  EXPECT_TRUE(std::isnan(s.residual_norm));
  EXPECT_FALSE(s.usable());
  s.status = Status::kConverged;
  EXPECT_TRUE(s.usable());
}

// ---------------------------------------------------------------------------------------------
// The traced case: a chaotic three-state model the catalogue does not have (Rössler), one
// output, RK4 at 0.05 s, written here as a user writes a model.

struct Rossler : ModelSizes<3, 0, 1> {
  double a = 0.2, b = 0.2, c = 5.7, dt = 0.05;
  template <typename T>
  State<T> rate(const State<T>& x) const {
    return State<T>(-x[1] - x[2], x[0] + a * x[1], b + x[2] * (x[0] - c));
  }
  template <typename T>
  State<T> f(const State<T>& x, const Input&, long) const {
    const State<T> k1 = rate<T>(x);
    const State<T> k2 = rate<T>(State<T>(x + 0.5 * dt * k1));
    const State<T> k3 = rate<T>(State<T>(x + 0.5 * dt * k2));
    const State<T> k4 = rate<T>(State<T>(x + dt * k3));
    return x + (dt / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return Output<T>(x[0]);
  }
};

// x⁺ = 0.9 x, y = 3 x: with Ψ = I the square window gives ∂G = 1 − 3 (ρ = 2, no contraction);
// Ψ = 0.3 contracts (ρ = 0.1).
struct Scaled1 : ModelSizes<1, 0, 1> {
  template <typename T>
  State<T> f(const State<T>& x, const Input&, long) const {
    return State<T>(0.9 * x[0]);
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return Output<T>(3.0 * x[0]);
  }
};

Measurements rossler_data(long steps) {
  SimulationOptions o;
  o.steps = steps;
  o.noise_std = 0.01;
  o.sample_time = 0.05;
  return simulate(Rossler{}, Eigen::Vector3d(-4.0, 3.0, 0.05), o);
}

SolverOptions window_solver_options() {
  SolverOptions o;
  o.stop.step_tolerance = 1e-10;
  o.stop.residual_tolerance = 1e-9;
  o.stop.max_iterations = 200;
  return o;
}

std::unique_ptr<WindowEstimator<Rossler>> rossler_estimator(const std::string& spec,
                                                            WindowGain gain) {
  WindowEstimatorOptions options;
  options.initial_estimate = Eigen::Vector3d::Zero();
  options.gain = gain;
  return make_window_estimator(Rossler{}, spec, options, window_solver_options());
}

int total_failures(const ObserverMetrics& m) {
  int total = 0;
  for (const auto& [name, count] : m.failures) total += count;
  return total;
}

std::vector<std::unique_ptr<Observer>> every_square_window_engine(WindowGain gain) {
  std::vector<std::unique_ptr<Observer>> observers;
  for (const char* spec : {"newton", "picard", "aitken", "steffensen", "anderson", "ceres"}) {
    observers.push_back(rossler_estimator(spec, gain));
  }
  return observers;
}

// The traced case itself (σ = 0.01): a square window of 3 samples 0.05 s apart amplifies the
// noise (errors of order 10 against the truth, for every engine alike), so what is checked is
// that every engine finds the window's own solution — Newton's — and never publishes a
// non-finite estimate or fails for long.
TEST(TracedCase, EverySquareWindowEngineFindsTheWindowSolution) {
  const Measurements data = rossler_data(600);
  auto observers = every_square_window_engine(WindowGain::kAuto);
  const RunResult r = run_observers(data, observers);
  const Eigen::MatrixXd& newton = r.estimates[0];
  EXPECT_EQ(r.metrics[0].failures.size(), 0u) << r.metrics[0].first_failure;
  for (size_t i = 0; i < observers.size(); ++i) {
    const ObserverMetrics& m = r.metrics[i];
    EXPECT_TRUE(r.estimates[i].allFinite()) << m.name;
    EXPECT_EQ(m.failures.count("non_finite_estimate"), 0u) << m.name;
    EXPECT_LT(total_failures(m), 60) << m.name << ": " << m.first_failure;
    long same = 0;
    for (long k = data.steps() - 100; k < data.steps(); ++k) {
      same += (r.estimates[i].col(k) - newton.col(k)).cwiseAbs().maxCoeff() < 1e-6;
    }
    EXPECT_GE(same, 90) << m.name << ": agrees with newton on " << same << " of the last 100";
  }
}

// Without noise the window solution is the truth: every engine reaches it.
TEST(TracedCase, EverySquareWindowEngineRecoversTheTruthWithoutNoise) {
  SimulationOptions o;
  o.steps = 600;
  o.sample_time = 0.05;
  const Measurements data = simulate(Rossler{}, Eigen::Vector3d(-4.0, 3.0, 0.05), o);
  auto observers = every_square_window_engine(WindowGain::kAuto);
  const RunResult r = run_observers(data, observers);
  for (size_t i = 0; i < observers.size(); ++i) {
    const ObserverMetrics& m = r.metrics[i];
    EXPECT_TRUE(r.estimates[i].allFinite()) << m.name;
    EXPECT_LT(total_failures(m), 20) << m.name << ": " << m.first_failure;
    const Eigen::MatrixXd tail = (r.estimates[i] - data.x).rightCols(500);
    EXPECT_LT(tail.cwiseAbs().maxCoeff(), 1e-6) << m.name << ": " << m.first_failure;
  }
}

TEST(TracedCase, IdentityGainWarnsAndNeverPublishesNonFinite) {
  const Measurements data = rossler_data(600);
  std::vector<std::unique_ptr<Observer>> observers;
  observers.push_back(rossler_estimator("steffensen", WindowGain::kIdentity));
  observers.push_back(rossler_estimator("picard", WindowGain::kIdentity));
  const RunResult r = run_observers(data, observers);
  for (size_t i = 0; i < observers.size(); ++i) {
    const ObserverMetrics& m = r.metrics[i];
    EXPECT_TRUE(r.estimates[i].allFinite()) << m.name;
    const auto warnings = observers[i]->info().warnings;
    ASSERT_EQ(warnings.size(), 1u) << m.name;
    EXPECT_NE(warnings[0].find("does not contract"), std::string::npos) << warnings[0];
    // Failures are counted and explained, never "none".
    EXPECT_GT(total_failures(m), 0) << m.name;
    EXPECT_FALSE(m.first_failure.empty()) << m.name;
  }
}

TEST(TracedCase, AutoGainChoosesNewtonWhereIdentityDoesNotContract) {
  auto estimator = rossler_estimator("picard", WindowGain::kAuto);
  const Measurements data = rossler_data(10);
  for (long k = 0; k < 3; ++k) estimator->step(k, data.t[k], data.y.col(k), Eigen::VectorXd(0));
  EXPECT_EQ(estimator->gain(), WindowGain::kNewton);
  ASSERT_EQ(estimator->info().warnings.size(), 1u);
  EXPECT_NE(estimator->info().warnings[0].find("chose psi = newton"), std::string::npos);
  // Engines that need no contraction keep the paper's Ψ = I, without a check.
  auto newton = rossler_estimator("newton", WindowGain::kAuto);
  for (long k = 0; k < 3; ++k) newton->step(k, data.t[k], data.y.col(k), Eigen::VectorXd(0));
  EXPECT_EQ(newton->gain(), WindowGain::kIdentity);
  EXPECT_TRUE(newton->info().warnings.empty());
}

// A user's engine that records every guess it is given and fails on the calls it is told to
// (returning a far-away point, as a diverged solve does); otherwise Newton.
template <int N>
class ScriptedEngine final : public Engine<N> {
 public:
  explicit ScriptedEngine(std::vector<int> failing)
      : Engine<N>(window_solver_options()), failing_(std::move(failing)), newton_({}, options()) {}
  std::string_view name() const override { return "scripted"; }
  Summary solve(const FixedPointProblem<N>& problem, Vector<N>& x) override {
    guesses.push_back(x);
    const int call = static_cast<int>(guesses.size()) - 1;
    Summary s;
    if (std::find(failing_.begin(), failing_.end(), call) == failing_.end()) {
      s = newton_.solve(problem, x);
    } else {
      s.engine = name();
      s.status = Status::kDiverged;
      x.setConstant(1e6);
      s.record_answer(x, options().stop);
    }
    usable.push_back(s.usable());
    return s;
  }
  std::vector<Vector<N>> guesses;
  std::vector<bool> usable;

 private:
  using Engine<N>::options;
  std::vector<int> failing_;
  NewtonEngine<N> newton_;
};

// After a failed solve the next guess is the coasted estimate of the window's first sample:
// neither the failed answer nor the warm start of the solve before it.
TEST(TracedCase, AFailedSolveIsNotTheNextWarmStart) {
  {  // N = 3 (Rössler): solves at k = 2 (usable), 3 (fails), 4.
    auto engine = std::make_unique<ScriptedEngine<3>>(std::vector<int>{1});
    ScriptedEngine<3>* scripted = engine.get();
    WindowEstimatorOptions options;
    options.initial_estimate = Eigen::Vector3d(-3.5, 2.5, 0.1);
    WindowEstimator<Rossler> estimator(Rossler{}, options, std::move(engine));
    const Measurements data = rossler_data(5);
    for (long k = 0; k < 5; ++k) estimator.step(k, data.t[k], data.y.col(k), Eigen::VectorXd(0));
    ASSERT_EQ(scripted->guesses.size(), 3u);
    ASSERT_TRUE(scripted->usable[0]);  // the k = 2 solve gave a warm start
    // The k = 2 answer w* (= x̂[0]) gave x̂[2] = f²(w*), kept for sample 2: the first sample
    // of the k = 4 window. The k = 3 guess was the warm start f(w*); its solve failed.
    const Rossler model;
    const Eigen::Vector3d warm = scripted->guesses[1];
    const Eigen::Vector3d expected = model.f<double>(warm, {}, 1);  // f(f(w*)) = x̂[2]
    EXPECT_LT((scripted->guesses[2] - expected).norm(), 1e-12)
        << scripted->guesses[2].transpose() << " vs " << expected.transpose();
    EXPECT_GT((scripted->guesses[2] - warm).norm(), 1e-6);
    EXPECT_LT(scripted->guesses[2].norm(), 1e3);  // not the failed answer
  }
  {  // N = 1 (y = 3x): the coasted guess is f(x̂[k−1]), not the x̂[k−1] kept in history.
    auto engine = std::make_unique<ScriptedEngine<1>>(std::vector<int>{1});
    ScriptedEngine<1>* scripted = engine.get();
    WindowEstimatorOptions options;
    options.initial_estimate = Vector<1>::Zero();
    options.gain = WindowGain::kIdentity;
    WindowEstimator<Scaled1> estimator(Scaled1{}, options, std::move(engine));
    for (long k = 0; k < 3; ++k) {
      const double x = 2.0 * std::pow(0.9, static_cast<double>(k));
      estimator.step(k, static_cast<double>(k), Eigen::VectorXd::Constant(1, 3.0 * x),
                     Eigen::VectorXd(0));
    }
    ASSERT_EQ(scripted->guesses.size(), 3u);
    ASSERT_TRUE(scripted->usable[0]);
    EXPECT_NEAR(scripted->guesses[1][0], 1.8, 1e-12);   // the warm start f(w*) after k = 0
    EXPECT_NEAR(scripted->guesses[2][0], 1.62, 1e-12);  // coasted f(x̂[1]) = f(f(x̂[0]))
  }
}

// ---------------------------------------------------------------------------------------------
// A guess at an unobservable point: the Lorenz origin (an equilibrium; y = x1 does not see x3
// to first order there).

TEST(SingularGuess, LorenzEquilibriumWarnsAndIsLeft) {
  const Discretized<Lorenz> lorenz(Lorenz{}, 0.01, Scheme::kRk4);
  SimulationOptions so;
  so.steps = 400;
  so.sample_time = 0.01;
  const Measurements data = simulate(lorenz, Eigen::Vector3d(1.0, 1.0, 1.0), so);
  std::vector<std::unique_ptr<Observer>> observers;
  WindowEstimatorOptions options;
  options.initial_estimate = Eigen::Vector3d::Zero();
  observers.push_back(make_window_estimator(lorenz, "newton", options, window_solver_options()));
  const RunResult r = run_observers(data, observers);
  const auto warnings = observers[0]->info().warnings;
  ASSERT_FALSE(warnings.empty());
  EXPECT_NE(warnings[0].find("singular point"), std::string::npos) << warnings[0];
  EXPECT_TRUE(r.estimates[0].allFinite());
  const Eigen::MatrixXd tail = (r.estimates[0] - data.x).rightCols(100);
  EXPECT_LT(tail.cwiseAbs().maxCoeff(), 1e-6) << r.metrics[0].first_failure;
  EXPECT_LT(total_failures(r.metrics[0]), 20) << r.metrics[0].first_failure;
}

// ---------------------------------------------------------------------------------------------
// The contraction check on a square window built for it: y = 3 x on x⁺ = 0.9 x gives
// ∂G = 1 − 3 (ρ = 2) with Ψ = I; Ψ = 0.3 contracts (ρ = 0.1).

TEST(ContractionWarning, OnANonContractingSquareWindow) {
  SimulationOptions so;
  so.steps = 30;
  const Measurements data = simulate(Scaled1{}, Eigen::VectorXd::Constant(1, 2.0), so);
  const auto run = [&](WindowGain gain, double scale) {
    WindowEstimatorOptions options;
    options.initial_estimate = Vector<1>::Zero();
    options.gain = gain;
    options.gain_scale = scale;
    std::vector<std::unique_ptr<Observer>> observers;
    observers.push_back(
        make_window_estimator(Scaled1{}, "picard", options, window_solver_options()));
    const RunResult r = run_observers(data, observers);
    return std::make_pair(observers[0]->info().warnings, r);
  };
  const auto [identity_warnings, identity] = run(WindowGain::kIdentity, 1.0);
  ASSERT_EQ(identity_warnings.size(), 1u);
  EXPECT_NE(identity_warnings[0].find("spectral radius of dG = I - Psi dH/dw is 2"),
            std::string::npos)
      << identity_warnings[0];
  EXPECT_GT(identity.metrics[0].failures.at("diverged"), 0);
  EXPECT_TRUE(identity.estimates[0].allFinite());

  const auto [scalar_warnings, scalar] = run(WindowGain::kScalar, 0.3);
  EXPECT_TRUE(scalar_warnings.empty());
  EXPECT_LT((scalar.estimates[0] - data.x).cwiseAbs().maxCoeff(), 1e-8);

  const auto [newton_warnings, newton] = run(WindowGain::kNewton, 1.0);
  EXPECT_TRUE(newton_warnings.empty());
  EXPECT_LT((newton.estimates[0] - data.x).cwiseAbs().maxCoeff(), 1e-8);
  EXPECT_LE(newton.metrics[0].iterations_max, 2);  // Ψ = (∂H)⁻¹ exact on a linear window

  WindowEstimatorOptions longer;  // Ψ has no meaning for a least-squares window
  longer.initial_estimate = Vector<1>::Zero();
  longer.window = 3;
  longer.gain = WindowGain::kNewton;
  EXPECT_THROW(make_window_estimator(Scaled1{}, "ceres", longer), InvalidInput);
  WindowEstimatorOptions bad;
  bad.initial_estimate = Vector<1>::Zero();
  bad.gain = WindowGain::kScalar;
  bad.gain_scale = 0.0;
  EXPECT_THROW(make_window_estimator(Scaled1{}, "picard", bad), InvalidInput);
}

// ---------------------------------------------------------------------------------------------
// Baselines that overflow: failures counted, estimates finite.

struct Linear2 : ModelSizes<2, 0, 1> {
  template <typename T>
  State<T> f(const State<T>& x, const Input&, long) const {
    return State<T>(0.9 * x[0] + 0.2 * x[1], -0.1 * x[0] + 0.8 * x[1]);
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return Output<T>(x[0]);
  }
};

TEST(Baselines, LuenbergerWithAnUnstableGainCountsFailuresAndStaysFinite) {
  SimulationOptions so;
  so.steps = 1500;
  const Measurements data = simulate(Linear2{}, Eigen::Vector2d(1.0, -1.0), so);
  std::vector<std::unique_ptr<Observer>> observers;
  LuenbergerOptions options;
  options.initial_estimate = Eigen::Vector2d::Zero();
  options.gain = Eigen::Vector2d(25.0, -40.0);
  observers.push_back(std::make_unique<LuenbergerObserver<Linear2>>(Linear2{}, options));
  const RunResult r = run_observers(data, observers);
  EXPECT_TRUE(r.estimates[0].allFinite());
  ASSERT_GT(r.metrics[0].failures.count("non_finite_estimate"), 0u);
  EXPECT_GT(r.metrics[0].failures.at("non_finite_estimate"), 1000);
  EXPECT_NE(r.metrics[0].first_failure.find("luenberger"), std::string::npos);
}

TEST(Baselines, EkfAndSlidingModeUnderAbsurdNoiseStayFinite) {
  // σ = 1e200 on the Rössler output: the estimates reach ~1e200 and z·x overflows in f.
  SimulationOptions so;
  so.steps = 300;
  so.sample_time = 0.05;
  so.noise_std = 1e200;
  const Measurements data = simulate(Rossler{}, Eigen::Vector3d(-4.0, 3.0, 0.05), so);
  std::vector<std::unique_ptr<Observer>> observers;
  EkfOptions ekf;
  ekf.initial_estimate = Eigen::Vector3d::Zero();
  observers.push_back(std::make_unique<ExtendedKalmanFilter<Rossler>>(Rossler{}, ekf));
  SlidingModeOptions sliding;
  sliding.initial_estimate = Eigen::Vector3d::Zero();
  sliding.q = Eigen::Vector3d(1.0, 1.0, 1.0);
  sliding.r = Eigen::Vector3d(1.0, 1.0, 1.0);
  sliding.gamma = 0.1;
  observers.push_back(std::make_unique<SlidingModeObserver<Rossler>>(Rossler{}, sliding));
  LuenbergerOptions luenberger;
  luenberger.initial_estimate = Eigen::Vector3d::Zero();
  luenberger.gain = Eigen::Vector3d(1.0, 0.5, 0.2);
  observers.push_back(std::make_unique<LuenbergerObserver<Rossler>>(Rossler{}, luenberger));
  const RunResult r = run_observers(data, observers);
  for (size_t i = 0; i < observers.size(); ++i) {
    EXPECT_TRUE(r.estimates[i].allFinite()) << r.metrics[i].name;
    EXPECT_GT(r.metrics[i].failures.count("non_finite_estimate"), 0u) << r.metrics[i].name;
    EXPECT_FALSE(r.metrics[i].first_failure.empty()) << r.metrics[i].name;
  }
}

// ---------------------------------------------------------------------------------------------
// The harness: a user's observer that publishes NaN is counted, never "none".

class NanObserver final : public Observer {
 public:
  NanObserver() { info_.name = "nan"; }
  void reset() override {}
  const ObserverStep& step(long k, double, const Eigen::VectorXd&,
                           const Eigen::VectorXd&) override {
    step_.estimate = Eigen::Vector2d(k > 3 ? kNaN : 0.0, 0.0);
    return step_;
  }

 private:
  ObserverStep step_;
};

// One that names one signal and publishes three from k = 2 on: refused by name, never written
// past the harness's table.
class BrokenPromiseObserver final : public Observer {
 public:
  BrokenPromiseObserver() {
    info_.name = "broken";
    info_.signals = {{"only"}};
  }
  void reset() override {}
  const ObserverStep& step(long k, double, const Eigen::VectorXd&,
                           const Eigen::VectorXd&) override {
    step_.estimate = Eigen::Vector2d::Zero();
    step_.signals = Eigen::VectorXd::Zero(k >= 2 ? 3 : 1);
    return step_;
  }

 private:
  ObserverStep step_;
};

// One that publishes what only the harness may add (the error in its coordinates): a report
// would read it in place of the harness's own row, so it is refused by name.
class ImpostorObserver final : public Observer {
 public:
  ImpostorObserver() {
    info_.name = "impostor";
    info_.signals = {{"my_error", SignalKind::kEmbeddedError}};
  }
  void reset() override {}
  const ObserverStep& step(long, double, const Eigen::VectorXd&, const Eigen::VectorXd&) override {
    step_.estimate = Eigen::Vector2d::Zero();
    step_.signals = Eigen::VectorXd::Zero(1);
    return step_;
  }

 private:
  ObserverStep step_;
};

TEST(Harness, AnObserverPublishingAHarnessKindIsRefused) {
  SimulationOptions so;
  so.steps = 3;
  const Measurements data = simulate(Linear2{}, Eigen::Vector2d(1.0, -1.0), so);
  std::vector<std::unique_ptr<Observer>> observers;
  observers.push_back(std::make_unique<ImpostorObserver>());
  EXPECT_NE(test::message_of([&] { run_observers(data, observers); })
                .find("run_observers: impostor publishes the signal 'my_error' of a kind only "
                      "the harness adds"),
            std::string::npos);
}

TEST(Harness, AnObserverPublishingOtherSizesThanItNamesIsRefused) {
  SimulationOptions so;
  so.steps = 10;
  const Measurements data = simulate(Linear2{}, Eigen::Vector2d(1.0, -1.0), so);
  std::vector<std::unique_ptr<Observer>> observers;
  observers.push_back(std::make_unique<BrokenPromiseObserver>());
  EXPECT_EQ(test::message_of([&] { run_observers(data, observers); }),
            "run_observers: broken at sample k = 2 published an estimate of 2 entries and 3 "
            "signals; expected 2 and 1 (ObserverInfo::signals)");
}

TEST(Harness, NonFiniteEstimatesAreFailures) {
  SimulationOptions so;
  so.steps = 10;
  const Measurements data = simulate(Linear2{}, Eigen::Vector2d(1.0, -1.0), so);
  std::vector<std::unique_ptr<Observer>> observers;
  observers.push_back(std::make_unique<NanObserver>());
  const RunResult r = run_observers(data, observers);
  EXPECT_EQ(r.metrics[0].failures.at("non_finite_estimate"), 6);
  EXPECT_NE(r.metrics[0].first_failure.find("k = 4"), std::string::npos)
      << r.metrics[0].first_failure;
}

// y = x1 + x2 on x⁺ = x: nothing tells x1 from x2, ∂H/∂w is singular everywhere. Newton says
// so at every window, and the first failure carries its status and message.
struct Unobservable : ModelSizes<2, 0, 1> {
  template <typename T>
  State<T> f(const State<T>& x, const Input&, long) const {
    return x;
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return Output<T>(x[0] + x[1]);
  }
};

TEST(Harness, FirstFailureHoldsTheEnginesStatusAndMessage) {
  SimulationOptions so;
  so.steps = 20;
  const Measurements data = simulate(Unobservable{}, Eigen::Vector2d(1.0, 2.0), so);
  std::vector<std::unique_ptr<Observer>> observers;
  WindowEstimatorOptions options;
  options.initial_estimate = Eigen::Vector2d(0.5, 0.5);
  observers.push_back(
      make_window_estimator(Unobservable{}, "newton", options, window_solver_options()));
  const RunResult r = run_observers(data, observers);
  const std::string& first = r.metrics[0].first_failure;
  EXPECT_NE(first.find("k = 1"), std::string::npos) << first;
  EXPECT_NE(first.find("newton: singular_jacobian"), std::string::npos) << first;
  EXPECT_NE(first.find("Jacobian of F is singular"), std::string::npos) << first;  // the message
  EXPECT_EQ(r.metrics[0].failures.at("singular_jacobian"), 19);
  EXPECT_TRUE(r.estimates[0].allFinite());
  ASSERT_FALSE(observers[0]->info().warnings.empty());
  EXPECT_NE(observers[0]->info().warnings[0].find("singular point"), std::string::npos);
}

// The simulation stops where the true state overflows instead of feeding NaN measurements.
TEST(Simulation, StopsWhereTheTrueStateIsNotFinite) {
  SimulationOptions so;
  so.steps = 100;
  test::Squaring exploding;
  exploding.scale = 1e10;  // overflows after a few steps from x = 2
  const Measurements data = simulate(exploding, Eigen::VectorXd::Constant(1, 2.0), so);
  EXPECT_LT(data.steps(), 100);
  EXPECT_GT(data.steps(), 0);
  EXPECT_TRUE(data.y.allFinite());
  EXPECT_TRUE(data.x.allFinite());
  EXPECT_NE(data.stop_message.find("not finite"), std::string::npos) << data.stop_message;
}

// ---------------------------------------------------------------------------------------------
// Reference adapters: success only for a finite point whose residual meets the tolerance.

TEST(References, KinsolFixedPointOnADivergingMapIsNotConverged) {
  // G(x) = 3x + 1: KINSOL's fixed-point iteration runs away to inf and NaN.
  const auto expanding = FixedPointProblem<2>::from_map(
      [](const Vector<2>& x, Vector<2>& g) { g = 3.0 * x + Vector<2>::Ones(); });
  reference::KinsolOptions ko;
  ko.strategy = reference::KinsolStrategy::kFixedPoint;
  ko.max_iterations = 2000;
  auto solver = reference::make_kinsol_solver(expanding, ko);
  Eigen::VectorXd x = Eigen::VectorXd::Constant(2, 0.1);
  const reference::KinsolResult r = solver->solve(x);
  // Measured: KINSOL returns KIN_SUCCESS after 648 iterations with u = inf; the adapter's own
  // check of the returned point is what says otherwise.
  EXPECT_GE(r.flag, 0) << r.flag_name << ": KINSOL itself claims success here";
  EXPECT_FALSE(r.success) << r.flag_name << " x = " << x.transpose();
  EXPECT_EQ(r.status(), "non_finite");
  EXPECT_FALSE(r.reason.empty());
  EXPECT_GE(r.evaluations, r.iterations);
}

TEST(References, KinsolCountsDifferenceQuotientEvaluations) {
  // Newton without a Jacobian: KINSOL's difference quotients evaluate F n times per Jacobian.
  const auto problem = FixedPointProblem<2>::from_map([](const Vector<2>& x, Vector<2>& g) {
    g = Vector<2>(0.5 * std::cos(x[1]), 0.5 * std::sin(x[0]));
  });
  reference::KinsolOptions ko;
  ko.strategy = reference::KinsolStrategy::kNewtonLineSearch;
  auto solver = reference::make_kinsol_solver(problem, ko);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(2);
  const reference::KinsolResult r = solver->solve(x);
  ASSERT_TRUE(r.success) << r.flag_name;
  EXPECT_GE(r.evaluations, r.iterations + 2 * r.jacobian_evaluations) << r.iterations;
}

TEST(References, KinsolsMaximumStepRuleFailsFromZeroAndTheSuitesDoesNot) {
  // F(u) = u − 50 from u₀ = 0: KINSOL's default maximum step is 1000 ‖u₀‖₂ but at least 1, so
  // the Newton step 50 is cut to 1 five times in a row: KIN_MXNEWT_5X_EXCEEDED.
  const auto shifted = FixedPointProblem<>::with_jacobian(
      [](const Eigen::VectorXd& u, Eigen::VectorXd& g) { g = 2.0 * u.array() - 50.0; },
      [](const Eigen::VectorXd&, Eigen::MatrixXd& j) { j.setConstant(1, 1, 2.0); }, 1);
  reference::KinsolOptions ko;
  ko.strategy = reference::KinsolStrategy::kNewtonLineSearch;
  Eigen::VectorXd u = Eigen::VectorXd::Zero(1);
  const reference::KinsolResult by_default = reference::make_kinsol_solver(shifted, ko)->solve(u);
  EXPECT_FALSE(by_default.success);
  EXPECT_EQ(by_default.flag_name, "KIN_MXNEWT_5X_EXCEEDED");
  ko.max_newton_step = 1000.0;  // the suite's 1000 max(1, ‖u₀‖₂)
  u.setZero();
  const reference::KinsolResult wider = reference::make_kinsol_solver(shifted, ko)->solve(u);
  EXPECT_TRUE(wider.success) << wider.flag_name;
  EXPECT_NEAR(u[0], 50.0, 1e-10);
  ko.max_newton_step = -1.0;
  EXPECT_THROW(reference::make_kinsol_solver(shifted, ko), std::invalid_argument);
}

TEST(References, StepTestsAloneAreNotSuccess) {
  // F(x) = x³ − 2 from x = 10 with a loose step tolerance (xtol 0.1 for hybrj; GSL's step test
  // 1e-3): the solvers stop on the step with |F| far above residual_tolerance (1e-8).
  const auto f = RootProblem<Dynamic>::with_autodiff(
      [](const auto& x) {
        using T = typename std::decay_t<decltype(x)>::Scalar;
        return Vector<Dynamic, T>(x.array().cube() - 2.0);
      },
      1, 1);
  reference::ReferenceOptions loose;
  loose.tolerance = 0.1;
  loose.minpack_xtol = 0.1;
  Eigen::VectorXd x = Eigen::VectorXd::Constant(1, 10.0);
  const reference::ReferenceResult minpack = reference::solve_minpack_hybrj(f, x, loose);
  EXPECT_EQ(minpack.status, "residual_above_tolerance") << "x = " << x[0];
  for (const char* method : {"hybridsj", "gnewton"}) {
    x = Eigen::VectorXd::Constant(1, 10.0);
    const reference::ReferenceResult r = reference::solve_gsl(method, f, x, loose);
    Eigen::VectorXd fx(1);
    f.evaluate(x, fx);
    if (std::abs(fx[0]) > loose.residual_tolerance) {
      EXPECT_NE(r.status, "converged") << method << ": |F| " << fx[0];
    }
  }
  // With the default tolerances every one of them converges, and says so.
  for (const char* method : {"hybridsj", "gnewton"}) {
    x = Eigen::VectorXd::Constant(1, 10.0);
    EXPECT_EQ(reference::solve_gsl(method, f, x, {}).status, "converged") << method;
  }
  x = Eigen::VectorXd::Constant(1, 10.0);
  EXPECT_EQ(reference::solve_minpack_hybrj(f, x, {}).status, "converged");
}

}  // namespace
}  // namespace nlobs
