// The MVT observer of [BMH]: the β problem (identity, row decoupling, degenerate pairs), the
// paper's two cases on the chaotic example (published structure and our output injection), the
// robot, the integrators, and bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "nlobs/models/discretization.hpp"
#include "nlobs/models/systems.hpp"
#include "nlobs/observers/core/simulation.hpp"
#include "nlobs/observers/mvt/mvt_observer.hpp"
#include "test_support.hpp"

namespace nlobs {
namespace {

constexpr double kStep = 1e-3;  // sample time and RK4 step of plant and observer

const Eigen::Vector3d kChaoticX0(-2.0, -1.0, -1.0), kChaoticXhat0(-1.0, -0.5, -1.5);
const Eigen::Vector3d kCase2Error(-1.0, -0.5, 0.2);  // the paper's case 2: 0.2 instead of 0.5
const Eigen::Vector4d kRobotX0(3, 3, 3, 3), kRobotXhat0(-1, -2, -0.5, -1);

template <typename Model>
Measurements simulate_continuous(const Model& model, const Eigen::VectorXd& x0, double t_end,
                                 std::function<Eigen::VectorXd(long)> input = {}) {
  SimulationOptions o;
  o.steps = std::lround(t_end / kStep) + 1;
  o.sample_time = kStep;
  o.input = std::move(input);
  return simulate(Discretized<Model>(model, kStep, Scheme::kRk4), x0, o);
}

Eigen::VectorXd robot_input(long k) {
  return Eigen::VectorXd::Constant(1, std::sin(static_cast<double>(k) * kStep));
}

// Per sample: ‖x − x̂‖₂ and ‖(x − x̂) − ê‖₂, and the largest ‖X(β)‖ seen.
struct Trace {
  std::vector<double> error, tracking;
  double max_residual = 0.0;
  int failures = 0;
  double max_error_from(double t) const {
    double worst = 0.0;
    for (size_t k = static_cast<size_t>(std::lround(t / kStep)); k < error.size(); ++k) {
      worst = std::max(worst, error[k]);
    }
    return worst;
  }
};

template <typename Model>
Trace run(MvtObserver<Model>& observer, const Measurements& data) {
  constexpr int n = Model::kStates;
  Trace trace;
  observer.reset();
  for (long k = 0; k < data.steps(); ++k) {
    const ObserverStep& s = observer.step(k, data.t[k], data.y.col(k), data.u.col(k));
    if (!s.failure.empty()) ++trace.failures;
    const Eigen::VectorXd e = data.x.col(k) - s.estimate;
    trace.error.push_back(e.norm());
    trace.tracking.push_back((e - s.signals.segment(1 + n, n)).norm());
    trace.max_residual = std::max(trace.max_residual, s.signals[0]);
  }
  return trace;
}

MvtOptions options(MvtVariant variant, MvtBetaMethod method = MvtBetaMethod::kPerRow) {
  MvtOptions o;
  o.sample_time = kStep;
  o.variant = variant;
  o.beta.method = method;
  return o;
}

// The options with x̂(0) and ê(0) set.
MvtOptions started(MvtOptions o, const Eigen::VectorXd& xhat0, const Eigen::VectorXd& ehat0) {
  o.initial_estimate = xhat0;
  o.initial_error_estimate = ehat0;
  return o;
}

// ---- the β problem -------------------------------------------------------------------------

template <typename Model>
void expect_mvt_identity(const Model& model, MvtBetaMethod method, unsigned seed) {
  constexpr int n = Model::kStates;
  using State = ModelVector<double, n>;
  MvtBetaOptions o;
  o.method = method;
  MvtBetaSolver<Model> solver(model, o);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> box(-2.0, 2.0);
  const typename MvtBetaSolver<Model>::Input u =
      MvtBetaSolver<Model>::Input::Constant(model.inputs(), 0.3);
  for (int trial = 0; trial < 50; ++trial) {
    State xhat, ehat;
    for (int i = 0; i < n; ++i) xhat[i] = box(rng), ehat[i] = box(rng);
    ASSERT_TRUE(solver.set_pair(xhat, ehat, u, 0.0));
    State beta = State::Constant(0.5);
    const MvtBetaResult r = solver.solve(beta);
    EXPECT_TRUE(r.converged) << "trial " << trial;
    EXPECT_LE(r.residual_norm, 1e-8) << "trial " << trial;
    EXPECT_GE(beta.minCoeff(), 0.0);
    EXPECT_LE(beta.maxCoeff(), 1.0);
    typename MvtBetaSolver<Model>::Jacobian d;
    solver.mvt_jacobian(beta, d);
    const State lhs = d * ehat, rhs = solver.f_w() - solver.f_xhat();  // D ê = F(x̂+ê) − F(x̂)
    EXPECT_LE((lhs - rhs).norm(), 1e-8 * (1.0 + rhs.norm())) << "trial " << trial;
  }
}

// x' = x³ whose derivative (the AD scalar only) throws inside (0.5625, 0.625) except at
// multiples of 1/16: with x̂ = 0, ê = 1 and one secant step, the β row's root (1/√3) is left to
// the grid and then to TOMS 748 inside that cell, where only the refinement evaluates.
struct ThrowsInsideACell : ModelSizes<1, 0, 1> {
  template <typename T>
  State<T> vector_field(const State<T>& x, const Input&, double) const {
    if constexpr (!std::is_same_v<T, double>) {
      const double v = x[0].a;
      if (v > 0.5625 && v < 0.625 && v * 16.0 != std::floor(v * 16.0)) {
        throw std::runtime_error("the model's derivative gave up at x = " + std::to_string(v));
      }
    }
    return State<T>(x[0] * x[0] * x[0]);
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return x;
  }
};

TEST(MvtBeta, AModelsExceptionInsideTheRootRefinementReachesTheCaller) {
  // Boost's own failures in TOMS 748 mean "no root refined"; the model's exception is the user's
  // and must not be swallowed as one of them.
  const ThrowsInsideACell model;
  MvtBetaOptions o;
  o.max_iterations = 1;
  MvtBetaSolver<ThrowsInsideACell> solver(model, o);
  using State = MvtBetaSolver<ThrowsInsideACell>::State;
  ASSERT_TRUE(solver.set_pair(State(0.0), State(1.0), {}, 0.0));
  State beta(0.1);
  try {
    solver.solve(beta);
    FAIL() << "no exception; beta = " << beta[0];
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("the model's derivative gave up"), std::string::npos)
        << e.what();
  }
}

TEST(MvtBeta, IdentityHoldsAtTheSolvedBetaOnRandomPairs) {
  for (MvtBetaMethod m : {MvtBetaMethod::kPerRow, MvtBetaMethod::kNlopt, MvtBetaMethod::kCeres}) {
    SCOPED_TRACE(std::string(to_string(m)));
    expect_mvt_identity(ChaoticNoLinear{}, m, 1);
    expect_mvt_identity(FlexibleJointRobot{}, m, 2);
  }
}

// Row decoupling: the joint engines, with no per-row help, land on the per-row roots. Both start
// from β = 0.2 (the bilinear rows' root is ½ exactly: they must move); row 1 (the logarithm) is
// the one with a β that depends on the pair.
TEST(MvtBeta, RowDecouplingGivesTheJointSolution) {
  const ChaoticNoLinear model;
  MvtBetaOptions row_options, joint_options;
  joint_options.polish_rows = false;
  MvtBetaSolver<ChaoticNoLinear> rows(model, row_options);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> box(-1.5, 1.5), small(-0.4, 0.4);
  for (MvtBetaMethod m : {MvtBetaMethod::kNlopt, MvtBetaMethod::kCeres}) {
    joint_options.method = m;
    MvtBetaSolver<ChaoticNoLinear> joint(model, joint_options);
    int compared = 0, first_row = 0;
    for (int trial = 0; trial < 60; ++trial) {
      Eigen::Vector3d xhat, ehat;
      for (int i = 0; i < 3; ++i) xhat[i] = box(rng), ehat[i] = small(rng);
      rows.set_pair(xhat, ehat, {}, 0.0);
      joint.set_pair(xhat, ehat, {}, 0.0);
      Eigen::Vector3d b_rows = Eigen::Vector3d::Constant(0.2), b_joint = b_rows;
      rows.solve(b_rows);
      const MvtBetaResult r = joint.solve(b_joint);
      EXPECT_LE(r.residual_norm, 1e-8) << to_string(m) << " trial " << trial;
      for (int i = 0; i < 3; ++i) {
        // Rows 2 and 3 are bilinear: X_i is affine in β_i with slope −ê ∇²F_i ê; compare where
        // that slope is clear of zero (elsewhere every β is a root).
        const double slope = std::abs(rows.residual_row(i, 1.0) - rows.residual_row(i, 0.0));
        if (slope < 1e-3) continue;
        EXPECT_NEAR(b_rows[i], b_joint[i], 1e-6) << to_string(m) << " trial " << trial;
        ++compared;
        first_row += i == 0;
      }
    }
    EXPECT_GE(compared, 120);
    EXPECT_GE(first_row, 20);
  }
}

TEST(MvtBeta, DegeneratePairKeepsBeta) {
  const ChaoticNoLinear model;
  MvtBetaSolver<ChaoticNoLinear> solver(model, {});
  const Eigen::Vector3d xhat(0.3, -0.2, 1.0);
  ASSERT_TRUE(solver.set_pair(xhat, Eigen::Vector3d::Zero(), {}, 0.0));
  Eigen::Vector3d beta(0.1, 0.7, 0.9);
  const MvtBetaResult r = solver.solve(beta);
  EXPECT_TRUE(r.degenerate);
  EXPECT_EQ(r.residual_norm, 0.0);
  EXPECT_EQ(beta, Eigen::Vector3d(0.1, 0.7, 0.9));
  // Numerically zero: x̂ + ê rounds to x̂.
  ASSERT_TRUE(solver.set_pair(xhat, Eigen::Vector3d::Constant(1e-30), {}, 0.0));
  EXPECT_TRUE(solver.solve(beta).degenerate);
  EXPECT_EQ(beta, Eigen::Vector3d(0.1, 0.7, 0.9));
}

TEST(MvtBeta, BadOptions) {
  const ChaoticNoLinear model;
  MvtBetaOptions o;
  o.tolerance = 0.0;
  EXPECT_NE(test::message_of([&] { MvtBetaSolver<ChaoticNoLinear> s(model, o); }).find("tolerance"),
            std::string::npos);
  o = {};
  o.method = MvtBetaMethod::kNlopt;
  o.nlopt_algorithm = "LN_BOBYQA";
  EXPECT_NE(
      test::message_of([&] { MvtBetaSolver<ChaoticNoLinear> s(model, o); }).find("gradient-based"),
      std::string::npos);
  EXPECT_NE(test::message_of([] { mvt_beta_method_from_string("bisection"); }).find("per-row"),
            std::string::npos);
}

// ---- the paper's chaotic example -----------------------------------------------------------

TEST(MvtObserver, Case1ErrorEstimateTracksTheTrueError) {
  const Measurements data = simulate_continuous(ChaoticNoLinear{}, kChaoticX0, 15.0);
  for (MvtVariant v : {MvtVariant::kPublished, MvtVariant::kOutputInjection}) {
    MvtObserver<ChaoticNoLinear> observer(
        ChaoticNoLinear{}, started(options(v), kChaoticXhat0, kChaoticX0 - kChaoticXhat0));
    const Trace trace = run(observer, data);
    EXPECT_EQ(trace.failures, 0);
    EXPECT_LE(*std::max_element(trace.tracking.begin(), trace.tracking.end()), 1e-6);
    EXPECT_LE(trace.error.back(), 1e-6);  // ‖x − x̂‖ at t = 15 (measured 2.4e-8)
    EXPECT_LE(trace.max_residual, 1e-8);
  }
}

// The published structure from ê(0) ≠ x(0) − x̂(0): ê decays to zero by itself while x3's
// error stays at 0.06–0.18 (measured 0.0584 at t = 25) — x̂3 never learns it.
TEST(MvtObserver, Case2PublishedLeavesTheUnmeasuredErrorUncorrected) {
  const Measurements data = simulate_continuous(ChaoticNoLinear{}, kChaoticX0, 25.0);
  MvtObserver<ChaoticNoLinear> observer(
      ChaoticNoLinear{}, started(options(MvtVariant::kPublished), kChaoticXhat0, kCase2Error));
  const Trace trace = run(observer, data);
  EXPECT_LE(trace.max_residual, 1e-8);
  EXPECT_LE(observer.ehat().norm(), 1e-9);     // ê has (nearly) vanished
  for (double t = 5.0; t <= 25.0; t += 2.5) {  // after ê's transient; x3's error dominates
    const double e = trace.error[static_cast<size_t>(std::lround(t / kStep))];
    EXPECT_GE(e, 0.05) << "t = " << t;
    EXPECT_LE(e, 0.2) << "t = " << t;
  }
}

TEST(MvtObserver, Case2WithOutputInjectionConverges) {
  const Measurements data = simulate_continuous(ChaoticNoLinear{}, kChaoticX0, 30.0);
  MvtObserver<ChaoticNoLinear> observer(
      ChaoticNoLinear{},
      started(options(MvtVariant::kOutputInjection), kChaoticXhat0, kCase2Error));
  const Trace trace = run(observer, data);
  EXPECT_LE(trace.max_residual, 1e-8);
  EXPECT_LE(trace.max_error_from(17.5), 1e-6);  // measured 6e-8 over [17.5, 30]
}

TEST(MvtObserver, JointBetaSolversGiveTheSameRun) {
  const Measurements data = simulate_continuous(ChaoticNoLinear{}, kChaoticX0, 3.0);
  MvtObserver<ChaoticNoLinear> rows(
      ChaoticNoLinear{},
      started(options(MvtVariant::kOutputInjection), kChaoticXhat0, kCase2Error));
  const Trace reference = run(rows, data);
  for (MvtBetaMethod m : {MvtBetaMethod::kNlopt, MvtBetaMethod::kCeres}) {
    MvtObserver<ChaoticNoLinear> joint(
        ChaoticNoLinear{},
        started(options(MvtVariant::kOutputInjection, m), kChaoticXhat0, kCase2Error));
    const Trace trace = run(joint, data);
    EXPECT_LE(trace.max_residual, 1e-8) << to_string(m);
    EXPECT_LE((joint.xhat() - rows.xhat()).norm(), 1e-9) << to_string(m);
    EXPECT_EQ(joint.info().engine, to_string(m));
  }
}

TEST(MvtObserver, AdaptiveIntegratorMatchesRk4) {
  const Measurements data = simulate_continuous(ChaoticNoLinear{}, kChaoticX0, 5.0);
  MvtOptions o = options(MvtVariant::kOutputInjection);
  MvtObserver<ChaoticNoLinear> rk4(ChaoticNoLinear{}, started(o, kChaoticXhat0, kCase2Error));
  o.integrator = MvtIntegrator::kDopri5;
  MvtObserver<ChaoticNoLinear> adaptive(ChaoticNoLinear{},
                                        started(o, kChaoticXhat0, kChaoticX0 - kChaoticXhat0));
  const Trace trace = run(adaptive, data);
  EXPECT_LE(*std::max_element(trace.tracking.begin(), trace.tracking.end()), 1e-6);
  MvtObserver<ChaoticNoLinear> adaptive2(ChaoticNoLinear{}, started(o, kChaoticXhat0, kCase2Error));
  run(rk4, data);
  run(adaptive2, data);
  EXPECT_LE((adaptive2.xhat() - rk4.xhat()).norm(), 1e-7);  // same data, two integrators
  EXPECT_GT((adaptive2.xhat() - data.x.col(data.steps() - 1)).norm(), 1e-5);  // not trivially
}

TEST(MvtObserver, ExactStartStaysExactWithBetaKept) {
  const Measurements data = simulate_continuous(ChaoticNoLinear{}, kChaoticX0, 2.0);
  MvtObserver<ChaoticNoLinear> observer(
      ChaoticNoLinear{},
      started(options(MvtVariant::kOutputInjection), kChaoticX0, Eigen::Vector3d::Zero()));
  const Trace trace = run(observer, data);
  EXPECT_EQ(trace.failures, 0);
  // The first samples interpolate y by lower-degree polynomials: measured 4.7e-9.
  EXPECT_LE(*std::max_element(trace.error.begin(), trace.error.end()), 1e-8);
  EXPECT_TRUE(observer.gains().allFinite());
}

TEST(MvtObserver, MissingSamplesAreBridged) {
  Measurements data = simulate_continuous(ChaoticNoLinear{}, kChaoticX0, 4.0);
  MvtObserver<ChaoticNoLinear> reference(
      ChaoticNoLinear{},
      started(options(MvtVariant::kOutputInjection), kChaoticXhat0, kCase2Error));
  run(reference, data);
  for (long k = 1000; k < 1005; ++k) data.y.col(k).setConstant(std::nan(""));
  MvtObserver<ChaoticNoLinear> gapped(
      ChaoticNoLinear{},
      started(options(MvtVariant::kOutputInjection), kChaoticXhat0, kCase2Error));
  const Trace trace = run(gapped, data);
  EXPECT_EQ(trace.failures, 0);
  EXPECT_TRUE(
      gapped.step(4001, 4001 * kStep, data.y.col(0).setConstant(std::nan("")), data.u.col(0))
          .measurement_missing);
  EXPECT_LE((gapped.xhat() - reference.xhat()).norm(), 1e-4);
}

// ---- the flexible-joint robot --------------------------------------------------------------

TEST(MvtObserver, RobotConvergesAndTheInjectionCorrectsTheUnmeasuredState) {
  const Measurements data = simulate_continuous(FlexibleJointRobot{}, kRobotX0, 10.0, robot_input);
  const Eigen::Vector4d other(4, 5, 3.5, 3);  // ê(0) ≠ x(0) − x̂(0) by 1 in x4
  MvtObserver<FlexibleJointRobot> published(
      FlexibleJointRobot{}, started(options(MvtVariant::kPublished), kRobotXhat0, other));
  MvtObserver<FlexibleJointRobot> injected(
      FlexibleJointRobot{}, started(options(MvtVariant::kOutputInjection), kRobotXhat0, other));
  const Trace p = run(published, data), i = run(injected, data);
  EXPECT_LE(p.max_residual, 1e-8);
  EXPECT_LE(i.max_residual, 1e-8);
  EXPECT_GE(p.error.back(), 1e-2);  // x4's error decays only through the plant (0.058 at 10 s)
  // The floor: y's kinks from the held input, interpolated by a cubic (measured 1.3e-6).
  EXPECT_LE(i.max_error_from(3.0), 5e-6);
}

// ---- bad input -----------------------------------------------------------------------------

// F(x) leaves its domain for x1 > 1 (NaN).
struct BrokenAbove : ModelSizes<2, 0, 1> {
  template <typename T>
  State<T> vector_field(const State<T>& x, const Input&, double) const {
    using std::sqrt;
    return State<T>(x[1], sqrt(1.0 - x[0]));
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return Output<T>(x[0]);
  }
};

// Double-only vector field: no AD, finite differences with a warning.
struct DoubleOnly : ModelSizes<2, 0, 1> {
  State<double> vector_field(const State<double>& x, const Input&, double) const {
    return State<double>(x[1], -std::sin(x[0]));
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return Output<T>(x[0]);
  }
};

TEST(MvtObserverBadInput, OptionsAndOutputMap) {
  const auto make = [](MvtOptions o) {
    return test::message_of([&] {
      MvtObserver<ChaoticNoLinear> m(ChaoticNoLinear{}, started(o, kChaoticXhat0, kCase2Error));
    });
  };
  MvtOptions o = options(MvtVariant::kPublished);
  o.eta = 0.5;
  EXPECT_NE(make(o).find("MvtOptions::eta must be finite and >= 1 (got 0.5)"), std::string::npos);
  o = options(MvtVariant::kPublished);
  o.sample_time = 0.0;
  EXPECT_NE(make(o).find("MvtOptions::sample_time must be finite and > 0 (got 0)"),
            std::string::npos);
  o = options(MvtVariant::kPublished);
  o.injection_gain = -1.0;
  EXPECT_NE(make(o).find("MvtOptions::injection_gain"), std::string::npos);
  o = options(MvtVariant::kPublished);
  o.substeps = 0;
  EXPECT_NE(make(o).find("MvtOptions::substeps must be >= 1 (got 0)"), std::string::npos);
  o = options(MvtVariant::kPublished);
  o.name.clear();
  EXPECT_NE(make(o).find("MvtOptions::name"), std::string::npos);
  // validate() alone tells what needs no model; the constructor then checks the sizes.
  o = started(options(MvtVariant::kPublished), kChaoticXhat0, Eigen::Vector2d(0.1, 0.1));
  EXPECT_NO_THROW(o.validate());
  EXPECT_NE(test::message_of([&] {
              MvtObserver<ChaoticNoLinear> m(ChaoticNoLinear{}, o);
            }).find("MvtOptions::initial_error_estimate must have 3 entries (got 2)"),
            std::string::npos);
  o.initial_error_estimate.resize(0);  // empty: ê(0) = 0
  MvtObserver<ChaoticNoLinear> zero_error(ChaoticNoLinear{}, o);
  EXPECT_EQ(zero_error.ehat(), Eigen::Vector3d::Zero());
  o.name = "my mvt";
  EXPECT_EQ(MvtObserver<ChaoticNoLinear>(ChaoticNoLinear{}, o).name(), "my mvt");
  EXPECT_NE(test::message_of([] {
              MvtObserver<ChaoticNoLinear>(ChaoticNoLinear{}, MvtOptions{});
            }).find("MvtOptions::initial_estimate must be given"),
            std::string::npos);
  EXPECT_NE(test::message_of([] {
              MvtObserver<ChaoticNoLinear> m(
                  ChaoticNoLinear{}, started(options(MvtVariant::kPublished),
                                             Eigen::Vector3d(0, std::nan(""), 0), kCase2Error));
            }).find("MvtOptions::initial_estimate must be given, every entry finite"),
            std::string::npos);
  // Duffing measures x2: C = [0 1] is not [I_m 0].
  const std::string c = test::message_of([] {
    MvtObserver<Duffing> m(Duffing{}, started(options(MvtVariant::kPublished),
                                              Eigen::Vector2d(1, 0), Eigen::Vector2d(0.1, 0.1)));
  });
  EXPECT_NE(c.find("C = [I_m 0]"), std::string::npos) << c;
}

TEST(MvtObserverBadInput, NonFiniteFKeepsTheLastGoodState) {
  // x1 grows as x2 = 1 pushes it past 1, where F turns NaN.
  Measurements data;
  const long steps = 1500;
  data.t = Eigen::VectorXd::LinSpaced(steps, 0.0, kStep * (steps - 1));
  data.y = (0.5 + data.t.array()).matrix().transpose();
  data.u.resize(0, steps);
  MvtObserver<BrokenAbove> observer(
      BrokenAbove{}, started(options(MvtVariant::kPublished), Eigen::Vector2d(0.5, 1.0),
                             Eigen::Vector2d(0.0, 0.0)));
  long first_failure = -1;
  Eigen::VectorXd last_good;
  for (long k = 0; k < steps; ++k) {
    const ObserverStep& s = observer.step(k, data.t[k], data.y.col(k), data.u.col(k));
    if (!s.failure.empty()) {
      first_failure = k;
      EXPECT_EQ(s.failure, "non_finite");
      EXPECT_NE(s.failure_message.find("not finite"), std::string::npos);
      EXPECT_EQ(s.estimate, last_good);
      break;
    }
    last_good = s.estimate;
  }
  EXPECT_GT(first_failure, 400);
  EXPECT_TRUE(observer.xhat().allFinite());
}

TEST(MvtObserverBadInput, ModelWithoutJetSupportFallsBackToFiniteDifferences) {
  MvtObserver<DoubleOnly> observer(
      DoubleOnly{}, started(options(MvtVariant::kPublished), Eigen::Vector2d(0.5, 0.0),
                            Eigen::Vector2d(0.2, -0.1)));
  ASSERT_EQ(observer.info().warnings.size(), 1u);
  EXPECT_NE(observer.info().warnings[0].find("central differences"), std::string::npos);
  const DoubleOnly model;
  MvtBetaSolver<DoubleOnly> solver(model, {});
  const Eigen::Vector2d xhat(0.5, 0.0), ehat(0.8, -0.3);
  ASSERT_TRUE(solver.set_pair(xhat, ehat, {}, 0.0));
  Eigen::Vector2d beta = Eigen::Vector2d::Constant(0.5);
  solver.solve(beta);
  Eigen::Matrix2d d;
  solver.mvt_jacobian(beta, d);
  EXPECT_LE((d * ehat - (solver.f_w() - solver.f_xhat())).norm(), 1e-6);
  EXPECT_NEAR(d(1, 0), -std::cos(0.5 + beta[1] * 0.8), 1e-7);
}

TEST(MvtObserverBadInput, NonFiniteInputKeepsTheState) {
  FlexibleJointRobot robot;
  MvtObserver<FlexibleJointRobot> observer(
      robot, started(options(MvtVariant::kOutputInjection), kRobotXhat0, kRobotX0 - kRobotXhat0));
  const Eigen::VectorXd y = kRobotX0.head<3>(), u = Eigen::VectorXd::Zero(1);
  observer.step(0, 0 * kStep, y, u);
  observer.step(1, 1 * kStep, y, u);
  const Eigen::Vector4d kept = observer.xhat();
  const ObserverStep& bad =
      observer.step(2, 2 * kStep, y, Eigen::VectorXd::Constant(1, std::nan("")));
  EXPECT_EQ(bad.failure, "non_finite");
  EXPECT_NE(bad.failure_message.find("u_k is not finite"), std::string::npos);
  EXPECT_EQ(observer.xhat(), kept);
  EXPECT_TRUE(observer.step(3, 3 * kStep, y, u).failure.empty());  // the next good sample goes on
  EXPECT_TRUE(observer.xhat().allFinite());
}

// A repeated sample is an error naming it; after reset() the observer starts again at k = 0.
TEST(MvtObserverBadInput, SamplesComeInOrderAndResetStartsAgain) {
  MvtObserver<ChaoticNoLinear> observer(
      ChaoticNoLinear{}, started(options(MvtVariant::kPublished), kChaoticXhat0, kCase2Error));
  const Eigen::VectorXd y = kChaoticX0.head<2>(), u(0);
  observer.step(0, 0 * kStep, y, u);
  const Eigen::Vector3d first = observer.step(1, 1 * kStep, y, u).estimate;
  EXPECT_NE(test::message_of([&] {
              observer.step(1, 1 * kStep, y, u);
            }).find("sample k = 1 does not come after"),
            std::string::npos);
  observer.reset();
  EXPECT_TRUE(observer.step(0, 0 * kStep, y, u).failure.empty());
  EXPECT_EQ(observer.step(1, 1 * kStep, y, u).estimate, first);  // the same run again
}

// Recorded times: the grid t_0 + k·T starts at the first sample (data from t_0 = 100 give the
// run from 0, to the rounding of y's interpolation times); a time off the grid is refused with
// the state held, and the next sample on it goes on.
TEST(MvtObserverBadInput, TimesMustLieOnTheSampleGrid) {
  Measurements data = simulate_continuous(ChaoticNoLinear{}, kChaoticX0, 1.0);
  const auto make = [] {
    return MvtObserver<ChaoticNoLinear>(
        ChaoticNoLinear{}, started(options(MvtVariant::kPublished), kChaoticXhat0, kCase2Error));
  };
  MvtObserver<ChaoticNoLinear> reference = make(), shifted = make(), jittered = make();
  for (long k = 0; k < data.steps(); ++k) {
    const Eigen::VectorXd y = data.y.col(k), u = data.u.col(k);
    const Eigen::VectorXd a = reference.step(k, data.t[k], y, u).estimate;
    const ObserverStep& b = shifted.step(k, 100.0 + data.t[k], y, u);
    ASSERT_TRUE(b.failure.empty()) << b.failure_message;
    EXPECT_LT((b.estimate - a).norm(), 1e-9) << k;
  }
  EXPECT_GT((reference.xhat() - kChaoticXhat0).norm(), 0.1);  // it moved: not a trivial match
  jittered.step(0, 0.0, data.y.col(0), data.u.col(0));
  const Eigen::Vector3d kept = jittered.xhat();
  const ObserverStep& off = jittered.step(1, 0.4 * kStep, data.y.col(1), data.u.col(1));
  EXPECT_EQ(off.failure, "non_uniform");
  EXPECT_NE(off.failure_message.find("off the uniform grid"), std::string::npos)
      << off.failure_message;
  EXPECT_EQ(jittered.xhat(), kept);
  EXPECT_EQ(jittered.step(2, std::nan(""), data.y.col(2), data.u.col(2)).failure, "non_finite");
  EXPECT_TRUE(jittered.step(3, 3 * kStep, data.y.col(3), data.u.col(3)).failure.empty());
  EXPECT_NE(jittered.xhat(), kept);
}

// A dropped row of recorded data (the time jumps by 2T while k goes on by one) is a gap,
// bridged like a missing y: the same estimates, bit for bit, as the run that saw it missing.
TEST(MvtObserverBadInput, ADroppedRowIsAGap) {
  const Measurements data = simulate_continuous(ChaoticNoLinear{}, kChaoticX0, 1.0);
  const auto make = [] {
    return MvtObserver<ChaoticNoLinear>(
        ChaoticNoLinear{}, started(options(MvtVariant::kPublished), kChaoticXhat0, kCase2Error));
  };
  MvtObserver<ChaoticNoLinear> missing = make(), dropped = make();
  long j = 0;
  for (long k = 0; k < data.steps(); ++k) {
    const bool gone = k == 700 || k == 701;
    Eigen::VectorXd y = data.y.col(k);
    if (gone) y.setConstant(std::nan(""));
    const Eigen::VectorXd a = missing.step(k, data.t[k], y, data.u.col(k)).estimate;
    if (gone) continue;  // the row never arrives
    const ObserverStep& b = dropped.step(j++, data.t[k], data.y.col(k), data.u.col(k));
    ASSERT_TRUE(b.failure.empty()) << k << ": " << b.failure_message;
    ASSERT_EQ(b.estimate, a) << k;
  }
  EXPECT_EQ(j, data.steps() - 2);
}

TEST(MvtObserverBadInput, WrongSampleSizeIsAnError) {
  MvtObserver<ChaoticNoLinear> observer(
      ChaoticNoLinear{}, started(options(MvtVariant::kPublished), kChaoticXhat0, kCase2Error));
  EXPECT_NE(test::message_of([&] {
              observer.step(0, 0 * kStep, Eigen::VectorXd::Zero(3), Eigen::VectorXd());
            }).find("the observer takes sizes 2 and 0"),
            std::string::npos);
}

}  // namespace
}  // namespace nlobs
