// A least-squares window's answer checked against the noise it was declared to carry
// (WindowEstimatorOptions::measurement_covariance): on a model nlobs does not ship whose window
// cost has a local minimum, the answer there is refused by name instead of published, and a
// consistent answer passes.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "nlobs/models/discretization.hpp"
#include "nlobs/observers/core/chi_squared.hpp"
#include "nlobs/observers/core/simulation.hpp"
#include "nlobs/observers/window/window_estimator.hpp"
#include "nlobs/registry/register_model.hpp"
#include "nlobs/runs/scenario_run.hpp"

namespace nlobs {
namespace {

// A constant θ seen through y = θ³ − 3θ: for θ = 2.1 (y = 2.961) the window cost
// Σ (y_j − w³ + 3w)² has its minimum at w = θ and a local one at w = −1, where the output's
// local maximum 2 stays 0.96 below every y — 96 σ for σ = 0.01. A Gauss–Newton-type engine
// started at −1.5 converges there.
struct Cubic : ModelSizes<1, 0, 1> {
  template <typename T>
  State<T> vector_field(const State<T>&, const Input&, double) const {
    return State<T>(T(0.0));
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return Output<T>(x[0] * x[0] * x[0] - 3.0 * x[0]);
  }
};

using Model = Discretized<Cubic>;
constexpr double kSigma = 0.01;
constexpr long kSamples = 100, kWindow = 5;

Measurements cubic_data() {
  SimulationOptions o;
  o.steps = kSamples;
  o.noise_std = kSigma;
  o.seed = 3;
  return simulate(Model(Cubic{}, 0.1), Eigen::VectorXd::Constant(1, 2.1), o);
}

ObserverMetrics run_window(double guess, bool declare_noise) {
  WindowEstimatorOptions o;
  o.initial_estimate = Eigen::VectorXd::Constant(1, guess);
  o.window = kWindow;
  if (declare_noise) o.measurement_covariance = Eigen::MatrixXd::Constant(1, 1, kSigma * kSigma);
  std::vector<std::unique_ptr<Observer>> observers;
  observers.push_back(make_window_estimator(Model(Cubic{}, 0.1), "levenberg-marquardt", o));
  RunResult r = run_observers(cubic_data(), observers);
  return r.metrics[0];
}

TEST(WindowConsistency, ChiSquaredQuantilesAreBoostMaths) {
  EXPECT_NEAR(chi_squared_quantile(1.0, 0.95), 3.841458820694124, 1e-12);
  EXPECT_NEAR(chi_squared_quantile(10.0, 0.999), 29.58829844507442, 1e-10);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const auto& [dof, p] :
       {std::pair{0.0, 0.5}, {-1.0, 0.5}, {nan, 0.5}, {1.0, 0.0}, {1.0, 1.0}, {1.0, nan}}) {
    EXPECT_THROW(chi_squared_quantile(dof, p), InvalidInput) << dof << " " << p;
  }
}

// Started at −1.5 every window converges to the local minimum −1. Without a declared noise each
// answer is published — the estimate sits 3.1 off θ for the whole run, "converged", with no
// failure: the silent wrong number. With R = σ² every one is refused by name (2V ≈ 4.5e4 against
// 23.5, the 0.9999 quantile of χ²(4)) and the estimate stays where it coasts, the guess.
TEST(WindowConsistency, ALocalMinimumIsRefusedNotPublished) {
  const ObserverMetrics silent = run_window(-1.5, false);
  EXPECT_TRUE(silent.failures.empty());
  EXPECT_GT(std::sqrt(silent.mse_after_window[0]), 3.0);

  const ObserverMetrics checked = run_window(-1.5, true);
  const long windows = kSamples - kWindow + 1;
  ASSERT_EQ(checked.failures.count("inconsistent_with_noise"), 1u)
      << checked.first_failure << " " << ::testing::PrintToString(checked.failures) << " mse "
      << checked.mse_after_window << " silent " << silent.mse_after_window;
  EXPECT_EQ(checked.failures.at("inconsistent_with_noise"), windows);
  EXPECT_NE(checked.first_failure.find("is inconsistent with the declared noise R: 2V = "),
            std::string::npos)
      << checked.first_failure;
  EXPECT_NE(checked.first_failure.find("quantile of chi2(4)"), std::string::npos)
      << checked.first_failure;
}

// Started near θ the answers are consistent: at most a few of the 96 are refused (1 in 10 000 is
// the check's false-refusal rate when all is right), and the estimate is at the noise floor.
TEST(WindowConsistency, AConsistentAnswerPasses) {
  const ObserverMetrics m = run_window(1.5, true);
  const auto refused =
      m.failures.count("inconsistent_with_noise") ? m.failures.at("inconsistent_with_noise") : 0;
  EXPECT_LE(refused, 2) << m.first_failure;
  EXPECT_LT(std::sqrt(m.mse_after_window[0]), kSigma);
}

TEST(WindowConsistency, BadOptionsAreRefusedByName) {
  const auto refused = [](const WindowEstimatorOptions& o, const std::string& words) {
    try {
      make_window_estimator(Model(Cubic{}, 0.1), "levenberg-marquardt", o);
      ADD_FAILURE() << words << ": accepted";
    } catch (const InvalidInput& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  WindowEstimatorOptions o;
  o.initial_estimate = Eigen::VectorXd::Constant(1, 1.5);
  o.window = kWindow;
  for (const double bad : {0.0, -1.0, 1.0, std::numeric_limits<double>::quiet_NaN()}) {
    WindowEstimatorOptions q = o;
    q.consistency_quantile = bad;
    refused(q, "WindowEstimatorOptions::consistency_quantile must be in (0, 1)");
  }
  for (const Eigen::MatrixXd& bad :
       {Eigen::MatrixXd(Eigen::MatrixXd::Constant(1, 1, 0.0)),
        Eigen::MatrixXd(Eigen::MatrixXd::Constant(1, 1, -1e-4)),
        Eigen::MatrixXd(Eigen::MatrixXd::Constant(1, 1, std::numeric_limits<double>::infinity())),
        Eigen::MatrixXd(Eigen::MatrixXd::Identity(2, 2))}) {
    WindowEstimatorOptions r = o;
    r.measurement_covariance = bad;
    refused(r, "WindowEstimatorOptions::measurement_covariance");
  }
}

// From a scenario: a simulated run declares its noise, so a least-squares window is checked
// against σ² I by default; the key measurement_covariance overrides it; recorded data declare
// none, and the window is then not checked (the same answers pass: the user must declare R).
TEST(WindowConsistency, AScenarioDeclaresItsSimulatedNoise) {
  static const bool registered = [] {
    model_registry().add(
        model_entry(ModelDefinition<Cubic>{.name = "cubic-test",
                                           .description = "y = theta^3 - 3 theta, theta constant",
                                           .default_step = 0.1}),
        "test_window_consistency");
    return true;
  }();
  (void)registered;
  const nlohmann::json spec = {
      {"name", "cubic"},
      {"model", {{"name", "cubic-test"}}},
      {"x0", {2.1}},
      {"initial_guess", {-1.5}},
      {"steps", kSamples},
      {"noise", kSigma},
      {"seed", 3},
      {"observers",
       {{{"type", "window"}, {"engine", "levenberg-marquardt"}, {"window", kWindow}},
        {{"type", "window"},
         {"engine", "levenberg-marquardt"},
         {"window", kWindow},
         {"measurement_covariance", 1.0}}}}};
  const Scenario s = parse_scenario(spec, "cubic");
  const ScenarioRun simulated = run_scenario(s);
  EXPECT_GT(simulated.result.metrics[0].failures.count("inconsistent_with_noise"), 0u);
  EXPECT_TRUE(simulated.result.metrics[1].failures.empty());  // R = 1: anything is consistent

  RunSettings recorded;
  recorded.data = simulated.prepared.data;
  recorded.data_source = "recorded.csv";
  const ScenarioRun from_file = run_scenario(s, std::move(recorded));
  EXPECT_TRUE(from_file.result.metrics[0].failures.empty());
}

}  // namespace
}  // namespace nlobs
