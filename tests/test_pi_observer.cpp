// The PI observer of [FFMG19]: the γ form against the direct form, the ultimate bounds against
// closed forms and simulation, bank composition, and bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "nlobs/observers/pi/pi_bank.hpp"
#include "nlobs/observers/pi/pi_bound.hpp"
#include "test_support.hpp"

namespace nlobs {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Classic RK4 for a 2-state system over [0, t_end].
template <typename Rhs>
Eigen::Vector2d rk4(Rhs rhs, Eigen::Vector2d x, double h, long steps,
                    const std::function<void(double, const Eigen::Vector2d&)>& visit) {
  for (long k = 0; k < steps; ++k) {
    const double t = h * static_cast<double>(k);
    const Eigen::Vector2d k1 = rhs(t, x), k2 = rhs(t + h / 2, x + h / 2 * k1),
                          k3 = rhs(t + h / 2, x + h / 2 * k2), k4 = rhs(t + h, x + h * k3);
    x += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    visit(t + h, x);
  }
  return x;
}

// s(t) and ṡ(t) known analytically; η = a ṡ + b(s) with a nonlinear b.
double s_of(double t) {
  return std::sin(2 * t) + 0.3 * t * t;
}
double ds_of(double t) {
  return 2 * std::cos(2 * t) + 0.6 * t;
}
double b_of(double s) {
  return 0.5 * s * s - s;
}

TEST(PiObserver, GammaFormEqualsDirectFormDrivenByTheExactDerivative) {
  const PiChannelConstants c{{8.0, 15.0}, 1.5};
  const Eigen::Vector2d start(0.7, -0.4);  // (η̂, η̂₁) at t = 0 for both forms
  const auto direct = [&](double t, const Eigen::Vector2d& e) {
    return pi_direct_rate(c.gains, e, c.a * ds_of(t) + b_of(s_of(t)));
  };
  const auto gamma = [&](double t, const Eigen::Vector2d& g) {
    return pi_gamma_rate(c, g, s_of(t), b_of(s_of(t)));
  };
  const double h = 1e-3;
  Eigen::Vector2d e = start, g = pi_gamma_for(c, start, s_of(0.0));
  double worst = 0.0;
  for (long k = 0; k < 5000; ++k) {
    const double t0 = h * static_cast<double>(k);
    e = rk4([&](double t, const Eigen::Vector2d& x) { return direct(t0 + t, x); }, e, h, 1,
            [](double, const Eigen::Vector2d&) {});
    g = rk4([&](double t, const Eigen::Vector2d& x) { return gamma(t0 + t, x); }, g, h, 1,
            [](double, const Eigen::Vector2d&) {});
    worst = std::max(worst, (pi_estimates(c, g, s_of(t0 + h)) - e).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(worst, 1e-9);
  EXPECT_GT(e.cwiseAbs().maxCoeff(), 1.0);  // the forms moved: the comparison is not of zeros
}

TEST(PiObserver, BankOnSamplesMatchesTheDirectFormToInterpolationAccuracy) {
  PiBank bank(1, 0);
  const auto y = bank.output(0);
  PiBank::Channel channel;
  channel.measured = y;
  channel.a = 1.5;
  channel.b = [y](const PiBank::Values& v) { return b_of(v[y]); };
  channel.gains = {8.0, 15.0};
  channel.initial_estimates = Eigen::Vector2d(0.7, -0.4);
  const auto eta = bank.add_pi("eta", channel);
  const double h = 1e-3;
  PiBankObserver observer(
      bank, {.name = "pi", .estimate = {eta.eta, eta.rate}, .sample_time = h, .substeps = 2});
  Eigen::Vector2d e(0.7, -0.4);
  double worst = 0.0;
  for (long k = 0; k <= 5000; ++k) {
    const double t = h * static_cast<double>(k);
    const auto& step =
        observer.step(k, t, Eigen::VectorXd::Constant(1, s_of(t)), Eigen::VectorXd());
    worst = std::max(worst, (step.estimate - e).cwiseAbs().maxCoeff());
    e = rk4(
        [&](double tau, const Eigen::Vector2d& x) {
          return pi_direct_rate(channel.gains, x, 1.5 * ds_of(t + tau) + b_of(s_of(t + tau)));
        },
        e, h, 1, [](double, const Eigen::Vector2d&) {});
  }
  // y is interpolated linearly between samples: O(h²) in s, amplified by k_p² a in the γ form.
  EXPECT_LT(worst, 1e-4);
  ASSERT_EQ(observer.info().signals.size(), 2u);  // the bank's stage signals, named by the bank
  EXPECT_EQ(observer.info().signals[0].name, "eta");
  EXPECT_EQ(observer.info().signals[1].name, "eta.rate");
  EXPECT_EQ(observer.info().signals[1].kind, SignalKind::kDiagnostic);
}

TEST(PiBound, L1GainMatchesClosedFormsForRealRoots) {
  // s / ((s + 3)(s + 5)): g = (5e^{−5t} − 3e^{−3t})/2 changes sign once, at t* = ln(5/3)/2, and
  // integrates to 0, so ∫|g| = 2 ∫₀^{t*} g = e^{−3t*} − e^{−5t*}.
  const double ts = std::log(5.0 / 3.0) / 2.0;
  EXPECT_NEAR(pi_l1_gain({8, 15}, 1, 0), std::exp(-3 * ts) - std::exp(-5 * ts), 1e-8);
  // 1 / (s² + k_p s + k_i) with real roots has a positive impulse response: ∫|g| = 1/k_i.
  EXPECT_NEAR(pi_l1_gain({8, 15}, 0, 1), 1.0 / 15.0, 1e-9);
  EXPECT_NEAR(pi_l1_gain({4, 4}, 0, 1), 1.0 / 4.0, 1e-9);  // repeated root
  // Complex roots a ± ib: ∫|e^{−at} sin(bt)/b| = coth(πa/(2b)) / (a² + b²).
  const auto damped = [](double kp, double ki) {
    const double a = kp / 2, b = std::sqrt(ki - a * a);
    return 1.0 / std::tanh(kPi * a / (2 * b)) / (a * a + b * b);
  };
  EXPECT_NEAR(pi_l1_gain({6, 25}, 0, 1), damped(6, 25), 1e-7 * damped(6, 25));
  // Lightly damped (1 600 periods to decay): the grid follows the oscillation.
  EXPECT_NEAR(pi_l1_gain({0.1, 100}, 0, 1), damped(0.1, 100), 1e-5 * damped(0.1, 100));
  // k_p² ≫ k_i: the slow root k_i/r2 must not cancel to 0.
  EXPECT_NEAR(pi_l1_gain({1e4, 1}, 0, 1), 1.0, 1e-6);
}

TEST(PiBound, PaperDeltaIsEq15WithRealEigenvaluesAndUndefinedOtherwise) {
  const double n = 2.0;
  const PiBound real = pi_ultimate_bound({8, 15}, n);  // eigenvalues of K: 3 and 5
  EXPECT_NEAR(real.paper_delta, std::sqrt(5.0 / 3.0) * 2 * n * std::sqrt(5.0) / 3.0, 1e-12);
  EXPECT_TRUE(real.warnings.empty());
  EXPECT_NEAR(real.eta_error, n * pi_l1_gain({8, 15}, 1, 0), 1e-12);
  // max(|g1|, |g2|) ≤ ‖(g1, g2)‖ ≤ |g1| + |g2|, with ∫|g2| = 1/k_i here (real roots).
  EXPECT_GE(real.error_norm, std::max(real.eta_error, n / 15.0));
  EXPECT_LE(real.error_norm, real.eta_error + n / 15.0);
  EXPECT_LT(real.error_norm, 0.99 * (real.eta_error + n / 15.0));

  const PiBound complex = pi_ultimate_bound({6, 25}, n);  // eigenvalues 3 ± 4i
  EXPECT_TRUE(std::isnan(complex.paper_delta));
  ASSERT_EQ(complex.warnings.size(), 1u);
  EXPECT_NE(complex.warnings[0].find("complex eigenvalues"), std::string::npos);
  EXPECT_TRUE(std::isfinite(complex.eta_error));
  const PiBound none = pi_ultimate_bound({6, 25}, 0.0);  // N = 0: warnings, zero bounds
  EXPECT_EQ(none.eta_error, 0.0);
  EXPECT_EQ(none.error_norm, 0.0);
  EXPECT_EQ(none.warnings.size(), 1u);
  // Larger gains shrink the ball: the trade-off the helper is for.
  EXPECT_LT(pi_ultimate_bound({40, 400}, n).eta_error, real.eta_error);
}

TEST(PiBound, BadInputIsRefused) {
  EXPECT_THROW(pi_ultimate_bound({-1, 15}, 1.0), InvalidInput);
  EXPECT_THROW(pi_ultimate_bound({8, 0}, 1.0), InvalidInput);
  EXPECT_THROW(pi_ultimate_bound({8, 15}, -1.0), InvalidInput);
  EXPECT_THROW(pi_ultimate_bound({8, 15}, std::nan("")), InvalidInput);
  EXPECT_NE(test::message_of([] {
              pi_ultimate_bound({-1, 15}, 1.0);
            }).find("k_p = -1"),
            std::string::npos);
}

// The bound is not loose by construction: a bang-bang Ω = N sign(g1(T − τ)) drives |e1(T)| to
// N ∫₀^T |g1|, which approaches eta_error.
TEST(PiBound, BangBangOmegaAttainsTheL1Bound) {
  const PiGains g{6, 25};
  const double n = 1.0, h = 1e-4, horizon = 6.0;
  const PiBound bound = pi_ultimate_bound(g, n);
  // g1(t): e1's impulse response, from E' = −K E with E(0) = (1, 0).
  const auto g1 = [&](double t) {
    const double w = 4.0;  // roots −3 ± 4i
    return std::exp(-3 * t) * (std::cos(w * t) - 0.75 * std::sin(w * t));
  };
  Eigen::Vector2d e = Eigen::Vector2d::Zero();
  const auto rhs = [&](double t, const Eigen::Vector2d& x) {
    const double omega = n * (g1(horizon - t) >= 0 ? 1.0 : -1.0);
    return Eigen::Vector2d(-g.kp * x[0] - g.ki * x[1] + omega, x[0]);
  };
  e = rk4(rhs, e, h, static_cast<long>(horizon / h), [](double, const Eigen::Vector2d&) {});
  EXPECT_NEAR(std::abs(e[0]), bound.eta_error, 2e-3 * bound.eta_error);
}

TEST(PiBank, TwoStageCascadeEstimatesVelocityThenAcceleration) {
  // y = sin t. Stage "v": η = ẏ = cos t. Stage "acc": η = d/dt v̂ on the signal v̂, ≈ −sin t.
  PiBank bank(1, 0);
  const auto v = bank.add_pi("v", {.measured = bank.output(0), .gains = {20, 200}});
  const auto acc = bank.add_pi("acc", {.measured = v.eta, .gains = {20, 200}});
  const double h = 1e-3;
  PiBankObserver observer(bank,
                          {.name = "cascade", .estimate = {v.eta, acc.eta}, .sample_time = h});
  const PiBound first = pi_ultimate_bound({20, 200}, 1.0);  // |d cos t / dt| ≤ 1
  double worst_v = 0, worst_acc = 0;
  for (long k = 0; k <= 20000; ++k) {
    const double t = h * static_cast<double>(k);
    const auto& s = observer.step(k, t, Eigen::VectorXd::Constant(1, std::sin(t)), {});
    if (t < 5.0) continue;
    worst_v = std::max(worst_v, std::abs(s.estimate[0] - std::cos(t)));
    worst_acc = std::max(worst_acc, std::abs(s.estimate[1] + std::sin(t)));
  }
  EXPECT_LE(worst_v, first.eta_error);
  // For a sinusoidal Ω the steady error is exactly the filter's gain at that frequency.
  EXPECT_NEAR(worst_v, pi_sinusoid_gain({20, 200}, 1.0), 0.02 * pi_sinusoid_gain({20, 200}, 1.0));
  // Stage 2 sees η = −sin t − ė_v: within its own bound plus the derivative of stage 1's error.
  EXPECT_LT(worst_acc, 2 * first.eta_error + pi_ultimate_bound({20, 200}, 1.0).eta_error);
}

TEST(PiBank, VectorEtaOnSeveralOutputs) {
  // y = (sin t, cos 2t): one channel per output, η_i = ẏ_i; each within its own bound.
  PiBank bank(2, 0);
  const auto a = bank.add_pi("a", {.measured = bank.output(0), .gains = {30, 300}});
  const auto b = bank.add_pi("b", {.measured = bank.output(1), .gains = {30, 300}});
  const double h = 1e-3;
  PiBankObserver observer(bank, {.name = "two", .estimate = {a.eta, b.eta}, .sample_time = h});
  double worst_a = 0, worst_b = 0;
  for (long k = 0; k <= 10000; ++k) {
    const double t = h * static_cast<double>(k);
    const auto& s = observer.step(k, t, Eigen::Vector2d(std::sin(t), std::cos(2 * t)), {});
    if (t < 3.0) continue;
    worst_a = std::max(worst_a, std::abs(s.estimate[0] - std::cos(t)));
    worst_b = std::max(worst_b, std::abs(s.estimate[1] + 2 * std::sin(2 * t)));
  }
  EXPECT_LE(worst_a, pi_ultimate_bound({30, 300}, 1.0).eta_error);  // |d cos t/dt| ≤ 1
  EXPECT_LE(worst_b, pi_ultimate_bound({30, 300}, 4.0).eta_error);  // |d(−2 sin 2t)/dt| ≤ 4
  EXPECT_GT(worst_b, worst_a);
}

TEST(PiBank, StagesMayOnlyReadEarlierSignals) {
  PiBank bank(1, 0);
  PiBank::Signal later{};
  const auto early =
      bank.add_signal("early", [&later](const PiBank::Values& v) { return v[later]; });
  later = bank.add_signal("later", [](const PiBank::Values& v) { return v.time(); });
  const std::string message = test::message_of(
      [&] { PiBankObserver(bank, {.name = "bad", .estimate = {early}, .sample_time = 0.01}); });
  EXPECT_NE(message.find("stage 'early' reads 'later'"), std::string::npos) << message;
  EXPECT_THROW(bank.add_signal("later", [](const PiBank::Values&) { return 0.0; }), InvalidInput);
  EXPECT_THROW(bank.add_pi("pi", {.measured = PiBank::Signal{99}, .gains = {1, 1}}), InvalidInput);
  EXPECT_THROW(bank.add_pi("neg", {.measured = bank.output(0), .gains = {-1, 1}}), InvalidInput);
  EXPECT_THROW(bank.add_pi("a0", {.measured = bank.output(0), .a = 0.0, .gains = {1, 1}}),
               InvalidInput);
  EXPECT_THROW(bank.output(1), InvalidInput);
  EXPECT_THROW(PiBankObserver(bank, {.name = "t", .estimate = {early}, .sample_time = 0.0}),
               InvalidInput);
  EXPECT_THROW(
      PiBankObserver(bank, {.name = "t", .estimate = {early}, .sample_time = 0.01, .substeps = 0}),
      InvalidInput);
}

TEST(PiBankOptions, ValidateNamesTheFieldAndValue) {
  PiBank bank(1, 0);  // signals y1, t, eta, eta.rate
  const auto eta = bank.add_pi("eta", {.measured = bank.output(0), .gains = {8, 15}});
  const PiBankOptions good{.estimate = {eta.eta, eta.rate}, .sample_time = 0.01};
  EXPECT_NO_THROW(good.validate());
  EXPECT_NO_THROW(PiBankObserver(bank, good));
  EXPECT_EQ(PiBankObserver(bank, good).name(), "pi_bank");
  const auto refusal = [](const PiBankOptions& o) {
    return test::message_of([&] { o.validate(); });
  };
  // One bad field each, the others as in `good`.
  const auto with = [&](const std::function<void(PiBankOptions&)>& change) {
    PiBankOptions o = good;
    change(o);
    return o;
  };
  const std::vector<std::pair<PiBankOptions, std::string>> cases = {
      {with([](PiBankOptions& o) { o.sample_time = 0.0; }),
       "PiBankOptions::sample_time must be finite and > 0 (got 0)"},
      {with([](PiBankOptions& o) { o.sample_time = std::nan(""); }),
       "PiBankOptions::sample_time must be finite and > 0 (got nan)"},
      {with([](PiBankOptions& o) { o.substeps = 0; }),
       "PiBankOptions::substeps must be >= 1 (got 0)"},
      {with([](PiBankOptions& o) { o.estimate.clear(); }),
       "PiBankOptions::estimate must list at least one signal (got {})"},
      {with([](PiBankOptions& o) { o.estimate[1] = PiBank::Signal{}; }),
       "PiBankOptions::estimate[1] must be a signal id >= 0 (got -1)"},
      {with([](PiBankOptions& o) { o.name.clear(); }),
       "PiBankOptions::name must not be empty (got \"\")"},
  };
  for (const auto& [options, expected] : cases) {
    const std::string message = refusal(options);
    EXPECT_NE(message.find(expected), std::string::npos) << message;
  }
  // The constructor refuses them alike: it calls validate() before its own checks.
  for (const auto& bad : cases) {
    EXPECT_EQ(test::message_of([&] { PiBankObserver(bank, bad.first); }), refusal(bad.first));
  }
  // A signal of another (larger) bank passes validate(): only the constructor knows the bank.
  const PiBankOptions foreign = with([](PiBankOptions& o) { o.estimate = {PiBank::Signal{17}}; });
  EXPECT_NO_THROW(foreign.validate());
  const std::string message = test::message_of([&] { PiBankObserver(bank, foreign); });
  EXPECT_NE(message.find(
                "PiBankOptions::estimate[0] must be one of the bank's 4 signals (got signal 17)"),
            std::string::npos)
      << message;
}

TEST(PiBank, MissingMeasurementsHoldTheStateAndTheGapIsIntegratedInSteps) {
  // y = 2t is linear, so interpolating across a gap gives the samples the gap lost: after the
  // gap, an observer that missed 200 samples must agree with one that saw them all.
  PiBank bank(1, 0);
  const auto eta = bank.add_pi("eta", {.measured = bank.output(0), .gains = {49, 700}});
  const double h = 1e-3;
  PiBankObserver full(bank, {.name = "full", .estimate = {eta.eta, eta.rate}, .sample_time = h});
  PiBankObserver gappy(bank, {.name = "gappy", .estimate = {eta.eta, eta.rate}, .sample_time = h});
  const auto t = [&](long k) { return h * static_cast<double>(k); };
  const auto y = [&](long k) { return Eigen::VectorXd::Constant(1, 2.0 * t(k)); };
  Eigen::VectorXd held;
  for (long k = 0; k < 400; ++k) {
    const Eigen::VectorXd reference = full.step(k, t(k), y(k), {}).estimate;
    const bool missing = k >= 100 && k < 300;
    const auto& s =
        gappy.step(k, t(k), missing ? Eigen::VectorXd::Constant(1, std::nan("")) : y(k), {});
    EXPECT_EQ(s.measurement_missing, missing);
    if (k == 99) held = s.estimate;
    if (missing) {
      EXPECT_EQ(s.estimate, held) << k;  // held, not coasting
    }
    if (k >= 300) {
      EXPECT_LT((s.estimate - reference).cwiseAbs().maxCoeff(), 1e-9) << k;
    }
  }
  EXPECT_THROW(gappy.step(400, t(400), Eigen::VectorXd::Zero(2), {}), InvalidInput);
}

TEST(PiBank, AFirstSampleWithNonFiniteSignalsDoesNotStart) {
  PiBank bank(1, 0);
  const auto y = bank.output(0);
  const auto inv = bank.add_signal("inverse", [y](const PiBank::Values& v) { return 1.0 / v[y]; });
  const auto eta = bank.add_pi(
      "eta", {.measured = inv, .gains = {8, 15}, .initial_estimates = Eigen::Vector2d::Zero()});
  PiBankObserver observer(bank, {.name = "pi", .estimate = {eta.eta}, .sample_time = 0.1});
  const auto& first = observer.step(0, 0.0, Eigen::VectorXd::Zero(1), {});
  EXPECT_EQ(first.failure, "non_finite");
  EXPECT_FALSE(first.ready);
  EXPECT_NE(first.failure_message.find("cannot start"), std::string::npos);
  const auto& second = observer.step(1, 0.1, Eigen::VectorXd::Constant(1, 2.0), {});
  EXPECT_TRUE(second.failure.empty());
  EXPECT_TRUE(second.ready);
  EXPECT_NEAR(second.estimate[0], 0.0, 1e-12);  // started here, from η̂ = 0
}

TEST(PiBank, AFailedAddLeavesNoStrayName) {
  PiBank bank(1, 0);
  bank.add_signal("x.rate", [](const PiBank::Values&) { return 0.0; });
  EXPECT_THROW(bank.add_pi("x", {.measured = bank.output(0), .gains = {1, 1}}), InvalidInput);
  EXPECT_EQ(bank.stage_signals().size(), 1u);
  EXPECT_NO_THROW(bank.add_signal("x", [](const PiBank::Values&) { return 1.0; }));
}

TEST(PiBank, NonFiniteSignalKeepsTheLastGoodStateAndSaysWhere) {
  // x = 1 / y leaves its domain when y crosses 0.
  PiBank bank(1, 0);
  const auto y = bank.output(0);
  const auto inv = bank.add_signal("inverse", [y](const PiBank::Values& v) { return 1.0 / v[y]; });
  const auto eta = bank.add_pi("eta", {.measured = inv, .gains = {8, 15}});
  PiBankObserver observer(bank, {.name = "pi", .estimate = {eta.eta}, .sample_time = 0.5});
  observer.step(0, 0.0, Eigen::VectorXd::Constant(1, 1.0), {});
  const Eigen::VectorXd good =
      observer.step(1, 0.5, Eigen::VectorXd::Constant(1, 0.5), {}).estimate;
  // [t1, t2] with y from 0.5 to −0.5: the RK4 midpoint hits y = 0.
  const auto& bad = observer.step(2, 1.0, Eigen::VectorXd::Constant(1, -0.5), {});
  EXPECT_EQ(bad.failure, "non_finite");
  EXPECT_NE(bad.failure_message.find("'inverse'"), std::string::npos) << bad.failure_message;
  EXPECT_NE(bad.failure_message.find("t = 0.75"), std::string::npos) << bad.failure_message;
  EXPECT_EQ(bad.estimate, good);
}

}  // namespace
}  // namespace nlobs
