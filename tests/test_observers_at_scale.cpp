// Observers on a model of run-time size (the reaction–diffusion chain, n in the hundreds): the
// model's equations and refusals; the EKF's sparse covariance propagation (traced pattern and
// compressed AD, or the dense Jacobian's nonzeros through AnyModel) gives the dense path's
// numbers and says which path it took; a model with a branch or one that cannot be traced falls
// back; the EKF, UKF, MHE and a least-squares window estimator track the chain from a wrong
// front; huge, non-finite and missing values are refused or reported, never a crash.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "chain_estimation.hpp"
#include "nlobs/models/discretization.hpp"
#include "nlobs/models/reaction_diffusion_chain.hpp"
#include "nlobs/observers/baselines/baselines.hpp"
#include "nlobs/observers/baselines/unscented_kalman_filter.hpp"
#include "nlobs/observers/core/any_model.hpp"
#include "nlobs/observers/mhe/mhe_estimator.hpp"
#include "nlobs/observers/window/window_estimator.hpp"
#include "nlobs/registry/model_registry.hpp"
#include "nlobs/registry/observer_types.hpp"

namespace nlobs {
namespace {

using Chain = ReactionDiffusionChain;
using test::chain_kalman_options;
using Sampled = Discretized<Chain>;

constexpr double kStep = 0.25;

Sampled chain(long cells, long sensors) {
  return Sampled(Chain({.cells = cells, .sensors = sensors}), kStep, Scheme::kRk4);
}

// The same chain with a comparison on x in its reaction (|x| written as a branch): the tracer
// counts it, and the pattern is declined.
struct BranchingChain : Chain {
  using Chain::Chain;
  template <typename T>
  State<T> vector_field(const State<T>& x, const Input& u, double t) const {
    State<T> dx = Chain::vector_field(x, u, t);
    if (x[0] > 0.5) dx[0] = dx[0] - 0.01 * x[0];
    return dx;
  }
};

// The plant from a front at cell n/4 and the outputs it gives, with measurement noise σ = 0.01.
struct Samples {
  std::vector<Eigen::VectorXd> states, outputs;
};
template <typename Model>
Samples simulate(const Model& model, const Eigen::VectorXd& x0, int samples, unsigned seed = 3) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.01);
  Samples run;
  Eigen::VectorXd x = x0;
  const Eigen::VectorXd u(0);
  for (int k = 0; k < samples; ++k) {
    Eigen::VectorXd y = model.h(x);
    for (Eigen::Index j = 0; j < y.size(); ++j) y[j] += noise(rng);
    run.states.push_back(x);
    run.outputs.push_back(y);
    x = model.f(x, u, k);
  }
  return run;
}

double rms(const Eigen::VectorXd& e) {
  return e.norm() / std::sqrt(static_cast<double>(e.size()));
}

// Runs the observer over the samples; returns the RMS error of each estimate.
std::vector<double> errors(Observer& observer, const Samples& run) {
  std::vector<double> out;
  const Eigen::VectorXd u(0);
  for (std::size_t k = 0; k < run.outputs.size(); ++k) {
    const ObserverStep& s =
        observer.step(static_cast<long>(k), static_cast<double>(k) * kStep, run.outputs[k], u);
    EXPECT_TRUE(s.failure.empty()) << "k = " << k << ": " << s.failure_message;
    out.push_back(rms(s.estimate - run.states[k]));
  }
  return out;
}

TEST(ReactionDiffusionChain, VectorFieldIsTheNagumoChainWithNoFluxEnds) {
  const Chain model({.cells = 4, .sensors = 2, .coupling = 2.0, .growth = 3.0, .threshold = 0.2});
  const Eigen::Vector4d x(0.1, 0.9, 0.4, 0.7);
  const auto reaction = [](double v) { return 3.0 * v * (1.0 - v) * (v - 0.2); };
  const Eigen::VectorXd f = model.vector_field(Eigen::VectorXd(x), Eigen::VectorXd(0), 0.0);
  EXPECT_NEAR(f[0], 2.0 * (x[1] - x[0]) + reaction(x[0]), 1e-15);
  EXPECT_NEAR(f[1], 2.0 * (x[0] - 2 * x[1] + x[2]) + reaction(x[1]), 1e-15);
  EXPECT_NEAR(f[3], 2.0 * (x[2] - x[3]) + reaction(x[3]), 1e-15);
  EXPECT_EQ(model.sensor_cells(), (std::vector<Eigen::Index>{1, 3}));
  EXPECT_EQ(model.h(Eigen::VectorXd(x)), Eigen::Vector2d(0.9, 0.7));
  // A front is 1 to its left, 0 to its right.
  const Eigen::VectorXd front = Chain({.cells = 100}).front(50.0, 2.0);
  EXPECT_GT(front[0], 0.999);
  EXPECT_LT(front[99], 0.001);
}

TEST(ReactionDiffusionChain, RefusesParametersAndStatesByName) {
  const auto refused = [](ReactionDiffusionChainParameters p, const std::string& field) {
    try {
      Chain model(p);
      ADD_FAILURE() << field << " accepted";
    } catch (const InvalidInput& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  refused({.cells = 1}, "cells");
  refused({.cells = 200'000'000}, "cells");
  refused({.cells = 10, .sensors = 0}, "sensors");
  refused({.cells = 10, .sensors = 11}, "sensors");
  refused({.coupling = std::nan("")}, "coupling");
  refused({.coupling = -1.0}, "coupling");
  refused({.growth = std::numeric_limits<double>::infinity()}, "growth");
  refused({.threshold = 1.0}, "threshold");
  const Chain model({.cells = 10, .sensors = 2});
  EXPECT_THROW(
      model.vector_field(Eigen::VectorXd(Eigen::VectorXd::Zero(9)), Eigen::VectorXd(0), 0.0),
      InvalidInput);
  EXPECT_THROW(model.h(Eigen::VectorXd(Eigen::VectorXd::Zero(11))), InvalidInput);
  EXPECT_THROW(model.front(std::nan(""), 1.0), InvalidInput);
  EXPECT_THROW(model.front(1.0, 0.0), InvalidInput);
}

// By name, as scenario files give it: the chain's sizes are whole numbers in range or refused by
// the parameter's name; the EKF's sparse_jacobian key is read and written back.
TEST(ReactionDiffusionChain, IsABuiltInModelOfRunTimeSize) {
  const nlohmann::json spec = {{"name", "reaction-diffusion"},
                               {"parameters", {{"cells", 150}, {"sensors", 5}}}};
  JsonReader reader(spec, "model");
  const ModelInstance model = make_model_instance(reader);
  EXPECT_EQ(model.discrete.states(), 150);
  EXPECT_EQ(model.discrete.outputs(), 5);
  for (const double cells : {2.5, -3.0, 1e12, 1.0}) {
    const nlohmann::json bad = {{"name", "reaction-diffusion"}, {"parameters", {{"cells", cells}}}};
    JsonReader bad_reader(bad, "model");
    try {
      make_model_instance(bad_reader);
      ADD_FAILURE() << "cells = " << cells << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("cells"), std::string::npos) << e.what();
    }
  }
  // The default 4 sensors do not fit 3 cells: the message says so with the cells.
  const nlohmann::json small = {{"name", "reaction-diffusion"}, {"parameters", {{"cells", 3}}}};
  JsonReader small_reader(small, "model");
  try {
    make_model_instance(small_reader);
    ADD_FAILURE() << "4 sensors on 3 cells accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'sensors'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("(cells = 3)"), std::string::npos) << e.what();
  }
  const nlohmann::json given = {{"type", "ekf"},
                                {"sparse_jacobian", false},
                                {"initial_covariance", 0.25},
                                {"measurement_covariance", 1e-3}};
  JsonReader ekf_reader(given, "observers[0]");
  const nlohmann::json written = observer_spec_json(parse_observer_spec(ekf_reader, model));
  EXPECT_EQ(written["sparse_jacobian"], false);
  // One number v is v I of the model's size: n × n for P0, p × p for R.
  ASSERT_EQ(written["initial_covariance"].size(), 150u);
  EXPECT_EQ(written["initial_covariance"][7].size(), 150u);
  EXPECT_EQ(written["initial_covariance"][7][7], 0.25);
  EXPECT_EQ(written["initial_covariance"][7][8], 0.0);
  ASSERT_EQ(written["measurement_covariance"].size(), 5u);
  EXPECT_EQ(written["measurement_covariance"][4][4], 1e-3);
  const nlohmann::json wrong = {{"type", "ekf"}, {"sparse_jacobian", "yes"}};
  JsonReader wrong_reader(wrong, "observers[0]");
  EXPECT_THROW(parse_observer_spec(wrong_reader, model), std::invalid_argument);
}

// The EKF's covariance with the sparse F equals the dense one's: same estimates, step by step.
TEST(EkfAtScale, SparsePropagationGivesTheDensePathsNumbers) {
  const Sampled model = chain(150, 5);
  const Samples run = simulate(model, model.model().front(40.0, 3.0), 40);
  const Eigen::VectorXd start = model.model().front(80.0, 3.0);
  EkfOptions sparse_options = chain_kalman_options<EkfOptions>(start);
  EkfOptions dense_options = sparse_options;
  dense_options.sparse_jacobian = false;
  ExtendedKalmanFilter<Sampled> sparse(model, sparse_options), dense(model, dense_options);
  ExtendedKalmanFilter<AnyModel> erased(AnyModel("chain", model, kStep), sparse_options);
  const Eigen::VectorXd u(0);
  for (std::size_t k = 0; k < run.outputs.size(); ++k) {
    const double t = static_cast<double>(k) * kStep;
    const long kk = static_cast<long>(k);
    const Eigen::VectorXd a = sparse.step(kk, t, run.outputs[k], u).estimate;
    const Eigen::VectorXd b = dense.step(kk, t, run.outputs[k], u).estimate;
    const Eigen::VectorXd c = erased.step(kk, t, run.outputs[k], u).estimate;
    ASSERT_LT((a - b).lpNorm<Eigen::Infinity>(), 1e-10) << "k = " << k;
    ASSERT_LT((c - b).lpNorm<Eigen::Infinity>(), 1e-10) << "k = " << k;
  }
  // One RK4 step of a tridiagonal field: bandwidth 4, 9 colours, 9 n − 20 entries.
  EXPECT_EQ(sparse.jacobian_note(), "sparse: traced, 150 x 150, 1330 entries, 9 colours");
  EXPECT_EQ(dense.jacobian_note(), "dense");
  EXPECT_NE(erased.jacobian_note().find("not traced"), std::string::npos) << erased.jacobian_note();
  EXPECT_NE(erased.jacobian_note().find("sparse product over the dense Jacobian's 1330 nonzeros"),
            std::string::npos)
      << erased.jacobian_note();
}

// A model that does not opt in to tracing (the default) gets the dense AD Jacobian and the sparse
// product over its exact zeros; samples at irregular times give flows of several lengths, each
// traced afresh on the chain (wider patterns for longer flows); all equal the dense path.
struct UntracedChain : Chain {
  static constexpr bool kTracesSparsity = false;
  using Chain::Chain;
};
TEST(EkfAtScale, UntracedModelsAndIrregularTimesGiveTheDensePathsNumbers) {
  // Flows of up to 4 RK4 steps: rows of up to 33 entries, within detection's n / 10 at n = 340.
  const Sampled model = chain(340, 5);
  const Discretized<UntracedChain> untraced(UntracedChain({.cells = 340, .sensors = 5}), kStep,
                                            Scheme::kRk4);
  const std::vector<double> times = {0.0, 0.25, 0.6, 0.85, 1.5, 1.75, 2.0, 2.3, 2.55, 3.4, 3.65};
  Eigen::VectorXd x = model.model().front(30.0, 3.0);
  const Eigen::VectorXd u(0);
  EkfOptions o = chain_kalman_options<EkfOptions>(model.model().front(50.0, 3.0));
  ExtendedKalmanFilter<Sampled> traced(model, o);
  ExtendedKalmanFilter<Discretized<UntracedChain>> plain(untraced, o);
  o.sparse_jacobian = false;
  ExtendedKalmanFilter<Sampled> dense(model, o);
  std::set<std::string> notes;
  for (std::size_t k = 0; k < times.size(); ++k) {
    if (k > 0) x = model.flow(x, u, times[k - 1], times[k] - times[k - 1]);
    const Eigen::VectorXd y = model.h(x);
    const long kk = static_cast<long>(k);
    const ObserverStep& a = traced.step(kk, times[k], y, u);
    ASSERT_TRUE(a.failure.empty()) << a.failure_message;
    const Eigen::VectorXd b = dense.step(kk, times[k], y, u).estimate;
    const Eigen::VectorXd c = plain.step(kk, times[k], y, u).estimate;
    ASSERT_LT((a.estimate - b).lpNorm<Eigen::Infinity>(), 1e-10) << "k = " << k;
    ASSERT_LT((c - b).lpNorm<Eigen::Infinity>(), 1e-10) << "k = " << k;
    if (k > 0) notes.insert(traced.jacobian_note());
  }
  EXPECT_GE(notes.size(), 2u);  // a step, and flows of other lengths: other patterns
  for (const std::string& note : notes) EXPECT_EQ(note.rfind("sparse: traced", 0), 0u) << note;
  EXPECT_NE(plain.jacobian_note().find("does not opt in"), std::string::npos)
      << plain.jacobian_note();
  EXPECT_NE(plain.jacobian_note().find("sparse product over the dense Jacobian's"),
            std::string::npos)
      << plain.jacobian_note();
}

TEST(EkfAtScale, BelowOneHundredStatesTheDensePathIsKept) {
  const Sampled model = chain(99, 3);
  ExtendedKalmanFilter<Sampled> ekf(model,
                                    chain_kalman_options<EkfOptions>(model.model().front(9, 3)));
  ekf.step(0, 0.0, Eigen::VectorXd::Constant(3, 0.5), Eigen::VectorXd(0));
  ekf.step(1, kStep, Eigen::VectorXd::Constant(3, 0.5), Eigen::VectorXd(0));
  EXPECT_EQ(ekf.jacobian_note(), "dense");
}

TEST(EkfAtScale, AModelThatBranchesOnTheStateIsNotTracedAndStillFiltered) {
  const Discretized<BranchingChain> model(BranchingChain({.cells = 120, .sensors = 4}), kStep,
                                          Scheme::kRk4);
  const Samples run = simulate(model, model.model().front(30.0, 3.0), 20);
  EkfOptions o = chain_kalman_options<EkfOptions>(model.model().front(60.0, 3.0));
  ExtendedKalmanFilter<Discretized<BranchingChain>> ekf(model, o);
  o.sparse_jacobian = false;
  ExtendedKalmanFilter<Discretized<BranchingChain>> dense(model, o);
  const Eigen::VectorXd u(0);
  for (std::size_t k = 0; k < run.outputs.size(); ++k) {
    const double t = static_cast<double>(k) * kStep;
    const Eigen::VectorXd a = ekf.step(static_cast<long>(k), t, run.outputs[k], u).estimate;
    const Eigen::VectorXd b = dense.step(static_cast<long>(k), t, run.outputs[k], u).estimate;
    ASSERT_LT((a - b).lpNorm<Eigen::Infinity>(), 1e-10) << "k = " << k;
  }
  EXPECT_NE(ekf.jacobian_note().find("compared a value that depends on x"), std::string::npos)
      << ekf.jacobian_note();
  EXPECT_NE(ekf.jacobian_note().find("sparse product"), std::string::npos) << ekf.jacobian_note();
}

// Started from a front 15 cells off, each estimator ends 100 times closer to the plant than
// the model run open loop from its start (which keeps its own front). With a sensor every fifth
// cell: with one every fifteenth, the fronts between sensors are barely observable and the EKF
// is still 0.1 off after 60 samples (docs/observers.md, "Observers at scale").
TEST(ObserversAtScale, EkfUkfAndMheTrackTheChainFromAWrongFront) {
  const long n = 120;
  const int samples = 40;
  const Sampled model = chain(n, 24);
  const Samples run = simulate(model, model.model().front(30.0, 3.0), samples);
  const Eigen::VectorXd start = model.model().front(45.0, 3.0);
  Eigen::VectorXd open_loop = start;
  for (int k = 0; k + 1 < samples; ++k) open_loop = model.f(open_loop, Eigen::VectorXd(0), k);
  const double open_loop_error = rms(open_loop - run.states.back());
  ASSERT_GT(open_loop_error, 0.25);

  ExtendedKalmanFilter<Sampled> ekf(model, chain_kalman_options<EkfOptions>(start));
  EXPECT_LT(errors(ekf, run).back(), 0.01 * open_loop_error);
  // α = 1 would put the sigma points √n = 11 standard deviations (5.5) from x̂, where an RK4
  // step of h = 0.25 is unstable for the cubic reaction: they blow up. α = 0.3: 1.6.
  UkfOptions ukf_options = chain_kalman_options<UkfOptions>(start);
  ukf_options.alpha = 0.3;
  UnscentedKalmanFilter<Sampled> ukf(model, ukf_options);
  EXPECT_LT(errors(ukf, run).back(), 0.01 * open_loop_error);
  MheOptions mhe_options = chain_kalman_options<MheOptions>(start);
  mhe_options.horizon = 4;
  MheEstimator<Sampled> mhe(model, mhe_options);
  EXPECT_LT(errors(mhe, run).back(), 0.01 * open_loop_error);
}

// A least-squares window over the chain (6 samples of 8 outputs for 24 states), solved by
// levenberg-marquardt: the window's Jacobian couples every state the sensors have seen, so it is
// dense (its cost per step is in docs/observers.md, "Observers at scale").
TEST(ObserversAtScale, ALeastSquaresWindowEstimatesTheChain) {
  const Sampled model = chain(24, 8);
  const Samples run = simulate(model, model.model().front(6.0, 2.0), 30);
  WindowEstimatorOptions o;
  o.initial_estimate = model.model().front(14.0, 2.0);
  o.window = 6;  // 48 outputs for 24 states
  auto window = make_window_estimator(model, "levenberg-marquardt", o);
  std::vector<double> e;
  const Eigen::VectorXd u(0);
  for (std::size_t k = 0; k < run.outputs.size(); ++k) {
    const ObserverStep& s =
        window->step(static_cast<long>(k), static_cast<double>(k) * kStep, run.outputs[k], u);
    if (s.ready) e.push_back(rms(s.estimate - run.states[k]));
  }
  ASSERT_FALSE(e.empty());
  EXPECT_LT(e.back(), 0.05);
}

// Hostile values: an estimate that overflows the model is refused at the step (the last finite
// estimate kept, the step says why); a missing sample coasts; NaN options are refused by name.
TEST(EkfAtScale, HugeAndMissingValuesAreReportedNotCrashed) {
  const Sampled model = chain(150, 5);
  ExtendedKalmanFilter<Sampled> ekf(
      model, chain_kalman_options<EkfOptions>(Eigen::VectorXd::Constant(150, 1e200)));
  const ObserverStep& first =
      ekf.step(0, 0.0, Eigen::VectorXd::Constant(5, 0.5), Eigen::VectorXd(0));
  EXPECT_TRUE(first.estimate.allFinite());
  const ObserverStep& second =
      ekf.step(1, kStep, Eigen::VectorXd::Constant(5, 0.5), Eigen::VectorXd(0));
  EXPECT_EQ(second.failure, "non_finite_estimate") << second.failure_message;
  EXPECT_TRUE(second.estimate.allFinite());

  ExtendedKalmanFilter<Sampled> coasting(
      model, chain_kalman_options<EkfOptions>(model.model().front(40, 3)));
  const ObserverStep& missing =
      coasting.step(0, 0.0, Eigen::VectorXd::Constant(5, std::nan("")), Eigen::VectorXd(0));
  EXPECT_TRUE(missing.measurement_missing);
  EXPECT_TRUE(missing.estimate.allFinite());

  EkfOptions bad = chain_kalman_options<EkfOptions>(model.model().front(40, 3));
  bad.initial_estimate[77] = std::nan("");
  EXPECT_THROW(ExtendedKalmanFilter<Sampled>(model, bad), InvalidInput);
}

}  // namespace
}  // namespace nlobs
