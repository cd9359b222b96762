// The adaptive (dopri5) and implicit (sdirk3) schemes of Discretized on models nlobs does not
// ship, where the solution is known: order and tolerance measured, the stiff test problem
// where explicit steps fail and the implicit one holds, AD Jacobians of the discrete map, and
// every way they refuse — by name, never a silent wrong number.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "nlobs/models/discretization.hpp"
#include "nlobs/models/reaction_diffusion_chain.hpp"
#include "nlobs/observers/core/move_covariance.hpp"
#include "nlobs/observers/core/simulation.hpp"
#include "nlobs/observers/window/output_window.hpp"
#include "nlobs/registry/json_reader.hpp"
#include "nlobs/registry/model_registry.hpp"
#include "nlobs/registry/register_model.hpp"
#include "nlobs/solvers/autodiff.hpp"

namespace nlobs {
namespace {

// The Prothero–Robinson problem [HW96] §IV.15: x' = λ (x − cos t) − sin t, x(t) = cos t +
// e^{λt} (x(0) − 1). λ = −1 is a smooth, non-stiff problem; λ = −10⁴ at h = 0.1 puts the stiff
// eigenvalue 10³ h-widths outside every explicit scheme's stability region. `evaluations`
// counts F on every scalar (sdirk3's Jacobians on Jets included): the cost per sample.
struct ProtheroRobinson : ModelSizes<1, 0, 1> {
  double lambda = -1.0;
  long* evaluations = nullptr;

  template <typename T>
  State<T> vector_field(const State<T>& x, const Input&, double t) const {
    if (evaluations) ++*evaluations;
    return State<T>(lambda * (x[0] - std::cos(t)) - std::sin(t));
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return x;
  }
  double exact(double t, double x0) const { return std::cos(t) + std::exp(lambda * t) * (x0 - 1); }
};

// A stiff linear system x' = A x with eigenvalues −1 and −10⁴ (coupled), for the exactness of
// the Jacobian: the discrete map of a linear ODE is linear, so its Jacobian is its columns.
struct StiffLinear : ModelSizes<2, 0, 2> {
  template <typename T>
  State<T> vector_field(const State<T>& x, const Input&, double) const {
    return State<T>(-x[0] + 100.0 * x[1], -1e4 * x[1]);
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return x;
  }
};

// x' = x², x(0) = 1: the solution 1 / (1 − t) leaves every bound at t = 1.
struct BlowUp : ModelSizes<1, 0, 1> {
  template <typename T>
  State<T> vector_field(const State<T>& x, const Input&, double) const {
    return State<T>(x[0] * x[0]);
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return x;
  }
};

using Scalar = Eigen::Matrix<double, 1, 1>;

double run(const Discretized<ProtheroRobinson>& model, long samples, double x0) {
  Scalar x(x0);
  for (long k = 0; k < samples; ++k) x = model.f(x, {}, k);
  return x[0];
}

TEST(IntegrationSchemes, NamesReadBack) {
  for (Scheme s : {Scheme::kEuler, Scheme::kRk4, Scheme::kDopri5, Scheme::kSdirk3}) {
    EXPECT_EQ(scheme_from_name(scheme_name(s)), s);
  }
  EXPECT_FALSE(scheme_from_name("RK4"));
  EXPECT_FALSE(scheme_from_name(""));
  EXPECT_FALSE(scheme_from_name(std::string("rk4\0", 4)));
}

// sdirk3 is third order: halving its step divides the error at t = 5 by 2³ (measured exponent
// within 0.25), through sub-steps as the fixed explicit schemes.
TEST(IntegrationSchemes, SdirkConvergesAtOrderThree) {
  const ProtheroRobinson smooth;
  const double h = 0.5, x0 = 2.0;
  double previous = 0.0;
  for (const int substeps : {2, 4, 8, 16}) {
    const Discretized<ProtheroRobinson> model(smooth, h,
                                              {.scheme = Scheme::kSdirk3, .substeps = substeps});
    const double error = std::abs(run(model, 10, x0) - smooth.exact(5.0, x0));
    if (previous > 0.0) {
      EXPECT_NEAR(std::log2(previous / error), 3.0, 0.25) << substeps;
    }
    previous = error;
  }
}

// dopri5's global error follows its tolerance: within 10 rtol at t = 5 for each tolerance, and
// smaller for each tighter one, while one step of h = 0.5 (its largest) would be 1e-4 off.
TEST(IntegrationSchemes, DormandPrinceMeetsItsTolerance) {
  const ProtheroRobinson smooth;
  const double x0 = 2.0, exact = smooth.exact(5.0, x0);
  double previous = std::numeric_limits<double>::infinity();
  for (const double rtol : {1e-4, 1e-6, 1e-8, 1e-10}) {
    const Discretized<ProtheroRobinson> model(
        smooth, 0.5,
        {.scheme = Scheme::kDopri5, .absolute_tolerance = rtol, .relative_tolerance = rtol});
    const double error = std::abs(run(model, 10, x0) - exact);
    EXPECT_LT(error, 10.0 * rtol) << rtol;
    EXPECT_LT(error, previous) << rtol;
    previous = error;
  }
}

// The stiff test problem at λ = −10⁴, h = 0.1, from x(0) = 2 (a fast transient, then cos t):
//   rk4 with one step per sample leaves every bound (|λh| = 1000 ≫ 2.79);
//   sdirk3 with one step per sample follows cos t to 1e-4 (L-stable: the transient is damped in
//   one step), at under 40 evaluations of F per sample (measured: 11, its Jacobian's one);
//   dopri5 follows it too, but its error control must keep h |λ| inside its region: over 1000
//   evaluations per sample (measured ≈ 2100), the cost of a stiff plant on an explicit scheme.
TEST(IntegrationSchemes, TheStiffTestProblemNeedsTheImplicitScheme) {
  long evaluations = 0;
  ProtheroRobinson stiff;
  stiff.lambda = -1e4;
  stiff.evaluations = &evaluations;
  const long samples = 50;
  const double t_end = 0.1 * samples, exact = stiff.exact(t_end, 2.0);

  const double explicit_end =
      run(Discretized<ProtheroRobinson>(stiff, 0.1, Scheme::kRk4), samples, 2.0);
  EXPECT_FALSE(std::abs(explicit_end) < 1e10) << explicit_end;

  evaluations = 0;
  const double implicit_end =
      run(Discretized<ProtheroRobinson>(stiff, 0.1, {.scheme = Scheme::kSdirk3}), samples, 2.0);
  EXPECT_LT(std::abs(implicit_end - exact), 1e-4) << implicit_end << " vs " << exact;
  EXPECT_LT(evaluations, 40 * samples) << evaluations;

  evaluations = 0;
  const double adaptive_end =
      run(Discretized<ProtheroRobinson>(stiff, 0.1, {.scheme = Scheme::kDopri5}), samples, 2.0);
  EXPECT_LT(std::abs(adaptive_end - exact), 1e-4) << adaptive_end << " vs " << exact;
  EXPECT_GT(evaluations, 1000 * samples) << evaluations;
}

template <typename Model>
Eigen::Matrix<double, Model::kStates, Model::kStates> move_jacobian(
    const Discretized<Model>& model, const ModelVector<double, Model::kStates>& x,
    const ModelVector<double, Model::kInputs>& u, long k) {
  constexpr int N = Model::kStates;
  auto f = [&](const auto& v) {
    using T = typename std::decay_t<decltype(v)>::Scalar;
    return ModelVector<T, N>(model.f(ModelVector<T, N>(v), u, k));
  };
  Matrix<N, N> jacobian;
  autodiff_jacobian<N, N>(f, x, jacobian);
  return jacobian;
}

// On a linear ODE each scheme's move is linear, x⁺ = R x: its AD Jacobian is R, whose columns
// are the moves of the unit vectors. For sdirk3 this checks the implicit-function derivative to
// rounding, for dopri5 that the AD path takes the steps the double path takes (here from the
// state (1, 1): the unit vectors take other steps, so only to its tolerance).
TEST(IntegrationSchemes, TheAdJacobianOfALinearMoveIsTheMove) {
  const Eigen::Vector2d x(1.0, 1.0);
  for (const auto& [scheme, accuracy] :
       {std::pair{Scheme::kSdirk3, 1e-13}, {Scheme::kDopri5, 1e-5}}) {
    const Discretized<StiffLinear> model(StiffLinear{}, 0.01, {.scheme = scheme});
    const Eigen::Matrix2d ad = move_jacobian(model, x, {}, 0);
    for (int j = 0; j < 2; ++j) {
      const Eigen::Vector2d column = model.f(Eigen::Vector2d(Eigen::Vector2d::Unit(j)), {}, 0);
      EXPECT_LT((ad.col(j) - column).norm(), accuracy * (1.0 + column.norm()))
          << scheme_name(scheme) << " column " << j << ": " << ad.col(j).transpose() << " vs "
          << column.transpose();
    }
    // The value on AD scalars is the double one, bit for bit.
    const auto jet = model.f(Eigen::Matrix<ceres::Jet<double, 2>, 2, 1>(
                                 ceres::Jet<double, 2>(x[0], 0), ceres::Jet<double, 2>(x[1], 1)),
                             {}, 0);
    const Eigen::Vector2d value = model.f(x, {}, 0);
    EXPECT_EQ(jet[0].a, value[0]) << scheme_name(scheme);
    EXPECT_EQ(jet[1].a, value[1]) << scheme_name(scheme);
  }
}

// Van der Pol at μ = 100 (stiff on its slow branches), x = (1.5, −0.3): the AD Jacobian of
// each scheme's move agrees with central differences of the move on doubles, at tolerances
// tight enough that the differences see the map's derivative and not its Newton or step-size
// noise. Here J varies along the step, so this checks that sdirk3 takes J at each converged
// stage, not at the step's start.
struct VanDerPol : ModelSizes<2, 0, 1> {
  double mu = 100.0;
  template <typename T>
  State<T> vector_field(const State<T>& x, const Input&, double) const {
    return State<T>(x[1], mu * ((1.0 - x[0] * x[0]) * x[1] - x[0]));
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return Output<T>(x[0]);
  }
};

TEST(IntegrationSchemes, TheAdJacobianOfANonlinearMoveAgreesWithDifferences) {
  const Eigen::Vector2d x(1.5, -0.3);
  for (Scheme scheme : {Scheme::kSdirk3, Scheme::kDopri5}) {
    const Discretized<VanDerPol> model(
        VanDerPol{}, 0.01,
        {.scheme = scheme, .absolute_tolerance = 1e-13, .relative_tolerance = 1e-12});
    const Eigen::Matrix2d ad = move_jacobian(model, x, {}, 0);
    for (int j = 0; j < 2; ++j) {
      const double d = 1e-5;
      Eigen::Vector2d up = x, down = x;
      up[j] += d;
      down[j] -= d;
      const Eigen::Vector2d column = (model.f(up, {}, 0) - model.f(down, {}, 0)) / (2.0 * d);
      EXPECT_LT((ad.col(j) - column).norm(), 1e-6 * column.norm())
          << scheme_name(scheme) << " column " << j << ": " << ad.col(j).transpose() << " vs "
          << column.transpose();
    }
  }
}

// Where the plant leaves every bound, the adaptive and the implicit scheme throw
// IntegrationFailure naming the scheme and the time, not a number; a simulation stops there as
// at a non-finite state, keeping the samples before it and saying why.
TEST(IntegrationSchemes, ABlowUpIsAnIntegrationFailureByName) {
  const Scalar one(1.0);
  for (const auto& [scheme, words] :
       {std::pair{Scheme::kDopri5, "dopri5: "}, {Scheme::kSdirk3, "sdirk3: Newton's iteration"}}) {
    const Discretized<BlowUp> model(BlowUp{}, 2.0, {.scheme = scheme});
    try {
      const Scalar x = model.f(one, {}, 0);
      ADD_FAILURE() << scheme_name(scheme) << " returned " << x;
    } catch (const IntegrationFailure& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
    SimulationOptions o;
    o.steps = 3;
    const Measurements data = simulate(model, one, o);
    EXPECT_EQ(data.steps(), 1) << scheme_name(scheme);
    EXPECT_EQ(data.x(0, 0), 1.0);
    const std::string& why = data.stop_message;
    EXPECT_EQ(why.rfind("stopped at sample 1 (t = 2): the move from sample 0 could not be "
                        "integrated: " +
                            std::string(words),
                        0),
              0u)
        << why;
  }
}

// Inside a window the same failure is a trial point that is not finite, not an exception out
// of the engine: H(w) from w = 1 on a grid of 0.75 is 1, then about 4 (x = 1 / (1 − t)), then
// NaN where the move over [0.75, 1.5] crosses the blow-up; an engine rejects such a trial as it
// does one where an explicit step overflowed. (The MHE's cost is +inf there,
// horizon_problem.hpp.)
TEST(IntegrationSchemes, AWindowSeesAFailedMoveAsNotFinite) {
  for (Scheme scheme : {Scheme::kDopri5, Scheme::kSdirk3}) {
    OutputWindow<Discretized<BlowUp>> window(
        Discretized<BlowUp>(BlowUp{}, 0.75, {.scheme = scheme}), 3);
    for (long k = 0; k < 3; ++k) {
      window.push(k, Eigen::VectorXd::Constant(1, 1.0), Eigen::VectorXd());
    }
    const Eigen::VectorXd h = window.map(Scalar(1.0));
    ASSERT_EQ(h.size(), 3);
    EXPECT_EQ(h[0], 1.0) << scheme_name(scheme);
    EXPECT_NEAR(h[1], 4.0, 0.5) << scheme_name(scheme);
    EXPECT_TRUE(std::isnan(h[2])) << scheme_name(scheme) << ": " << h[2];
  }
}

// A state that is not finite is not integrated: the result is not finite (for the caller to
// judge, as after an explicit step that overflowed), at once and without a throw.
TEST(IntegrationSchemes, ANonFiniteStateStaysNonFinite) {
  const ProtheroRobinson smooth;
  for (Scheme scheme : {Scheme::kDopri5, Scheme::kSdirk3}) {
    const Discretized<ProtheroRobinson> model(smooth, 0.1, {.scheme = scheme});
    for (const double bad :
         {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
      EXPECT_FALSE(std::isfinite(model.f(Scalar(bad), {}, 0)[0])) << scheme_name(scheme);
    }
    // Huge but finite, where the problem is linear: the decay e^{−h} of x − cos t, not a
    // refusal.
    EXPECT_NEAR(model.f(Scalar(1e300), {}, 0)[0] / 1e300, std::exp(-0.1), 1e-5)
        << scheme_name(scheme);
  }
}

TEST(IntegrationSchemes, BadTolerancesAreRefusedByName) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const auto refused = [](const DiscretizationOptions& options, const std::string& field,
                          double bad) {
    try {
      Discretized<ProtheroRobinson>({}, 0.1, options);
      ADD_FAILURE() << field << " = " << bad << " accepted";
    } catch (const InvalidInput& e) {
      EXPECT_NE(std::string(e.what()).find("DiscretizationOptions::" + field + " = "),
                std::string::npos)
          << e.what();
    }
  };
  for (const double bad : {0.0, -1e-8, nan, inf}) {
    refused({.scheme = Scheme::kDopri5, .absolute_tolerance = bad}, "absolute_tolerance", bad);
  }
  for (const double bad : {1e-13, 0.0, 1.5, nan, -inf}) {
    refused({.scheme = Scheme::kSdirk3, .relative_tolerance = bad}, "relative_tolerance", bad);
  }
}

// sdirk3 is dense (its AD Jacobian of a move costs O(n⁴ / 8)): above 200 states it is refused at
// construction, by name; dopri5 has no such limit.
TEST(IntegrationSchemes, TheImplicitSchemeRefusesLargeSystems) {
  const ReactionDiffusionChain chain({.cells = 201, .sensors = 4});
  try {
    Discretized<ReactionDiffusionChain>(chain, 0.25, {.scheme = Scheme::kSdirk3});
    ADD_FAILURE() << "sdirk3 at n = 201 accepted";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("n = 201 states is above its limit of 200"),
              std::string::npos)
        << e.what();
  }
  const Discretized<ReactionDiffusionChain> adaptive(chain, 0.25, {.scheme = Scheme::kDopri5});
  Eigen::VectorXd x = Eigen::VectorXd::Zero(201);
  x.head(50).setOnes();
  EXPECT_TRUE(adaptive.f(x, ModelVector<double, 0>(), 0).allFinite());
}

// dopri5 at n = 10^5 (the reaction–diffusion chain, run-time size): one sample from a front at
// n / 4 agrees with 64 RK4 steps to its tolerance's order and stays finite and in [−0.5, 1.5].
TEST(IntegrationSchemes, DormandPrinceAtAHundredThousandStates) {
  const long n = 100000;
  const ReactionDiffusionChain chain({.cells = n, .sensors = 8});
  const Discretized<ReactionDiffusionChain> adaptive(chain, 0.25, {.scheme = Scheme::kDopri5});
  const Discretized<ReactionDiffusionChain> fine(chain, 0.25,
                                                 {.scheme = Scheme::kRk4, .substeps = 64});
  Eigen::VectorXd x(n);
  for (long i = 0; i < n; ++i) x[i] = i < n / 4 ? 1.0 : 0.0;
  const ModelVector<double, 0> u;
  const Eigen::VectorXd moved = adaptive.f(x, u, 0);
  EXPECT_TRUE(moved.allFinite());
  EXPECT_GT(moved.minCoeff(), -0.5);
  EXPECT_LT(moved.maxCoeff(), 1.5);
  EXPECT_NE(moved, x);
  EXPECT_LT((moved - fine.f(x, u, 0)).lpNorm<Eigen::Infinity>(), 1e-4);
}

// The EKF's covariance propagation traces the pattern of a move only for the fixed explicit
// schemes: dopri5's steps follow the values (a pattern traced at one state could miss entries
// at another) and sdirk3's move is dense. The Jacobian it falls back on is still exact.
TEST(IntegrationSchemes, OnlyFixedStepsAreTraced) {
  const long n = 100;  // SparsityDetectionRule::kSmallestSize: the least n that is traced
  const ReactionDiffusionChain chain({.cells = n, .sensors = 4});
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  x.head(n / 4).setOnes();
  const ModelVector<double, 0> u;
  const Eigen::MatrixXd p = Eigen::MatrixXd::Identity(n, n), q = 1e-4 * p;
  Eigen::MatrixXd traced, untraced;
  for (Scheme scheme : {Scheme::kRk4, Scheme::kDopri5, Scheme::kSdirk3}) {
    using Model = Discretized<ReactionDiffusionChain>;
    const Model model(chain, 0.05, {.scheme = scheme});
    detail::MoveCovariance<Model> propagation;
    Eigen::MatrixXd out;
    propagation.propagate(model, x, u, ModelStep{}, p, q, out);
    EXPECT_TRUE(out.allFinite()) << scheme_name(scheme);
    const bool is_traced = propagation.note().rfind("sparse: traced", 0) == 0;
    EXPECT_EQ(is_traced, scheme == Scheme::kRk4)
        << scheme_name(scheme) << ": " << propagation.note();
    if (scheme != Scheme::kRk4) {
      EXPECT_NE(propagation.note().find("traceable() is false"), std::string::npos)
          << propagation.note();
    }
  }
}

// From a scenario file: "scheme" takes every name, the tolerances reach the discretisation, and
// each bad value is refused naming its key path (a hostile name comes back escaped).
TEST(IntegrationSchemes, TheModelSpecTakesSchemesAndTolerances) {
  ModelRegistry registry("model");
  registry.add(model_entry(ModelDefinition<ProtheroRobinson>{
      .name = "pr", .description = "Prothero-Robinson", .default_step = 0.1}));
  const auto instance = [&](const nlohmann::json& spec) {
    JsonReader reader(spec, "scenario.model");
    return make_model_instance(reader, registry);
  };
  const ModelInstance m = instance({{"name", "pr"},
                                    {"scheme", "sdirk3"},
                                    {"absolute_tolerance", 1e-9},
                                    {"relative_tolerance", 1e-7}});
  EXPECT_EQ(m.discretization.scheme, Scheme::kSdirk3);
  EXPECT_EQ(m.discretization.absolute_tolerance, 1e-9);
  EXPECT_EQ(m.discretization.relative_tolerance, 1e-7);
  const Discretized<ProtheroRobinson> same({}, 0.1, m.discretization);
  EXPECT_EQ(m.discrete.f(Eigen::VectorXd(Eigen::VectorXd::Constant(1, 2.0)), Eigen::VectorXd(), 3),
            Eigen::VectorXd(same.f(Scalar(2.0), {}, 3)));
  EXPECT_EQ(instance({{"name", "pr"}, {"scheme", "dopri5"}}).discretization.scheme,
            Scheme::kDopri5);

  const auto refused = [&](const nlohmann::json& spec, const std::string& words) {
    try {
      instance(spec);
      ADD_FAILURE() << spec << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  refused({{"name", "pr"}, {"scheme", "rk45"}},
          "scheme 'rk45' is not one of euler, rk4, dopri5, sdirk3");
  refused({{"name", "pr"}, {"scheme", "a'\n\"b"}}, "scheme 'a'\\x0a\"b'");
  refused({{"name", "pr"}, {"absolute_tolerance", -1}},
          "scenario.model: DiscretizationOptions::absolute_tolerance = -1");
  refused({{"name", "pr"}, {"relative_tolerance", 1e-13}},
          "scenario.model: DiscretizationOptions::relative_tolerance = 1e-13");
  refused({{"name", "pr"}, {"relative_tolerance", "tight"}},
          "scenario.model: 'relative_tolerance'");
}

}  // namespace
}  // namespace nlobs
