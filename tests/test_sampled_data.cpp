// The sampled-data skeleton (sampled_data.hpp) and the one interval integrator
// (interval_integrator.hpp) that the MVT, high-gain and PI-bank observers share: each rule once
// here, on an ODE with a known solution, and through the PI bank and the MVT observer (the
// families' own tests cover the rest).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "nlobs/observers/core/interval_integrator.hpp"
#include "nlobs/observers/core/sampled_data.hpp"
#include "nlobs/observers/pi/pi_bank.hpp"
#include "test_support.hpp"

namespace nlobs {
namespace {

// s' = −s, s(0) = 1: s(t) = e^{−t}.
bool decay(double, const double* s, double* ds) {
  ds[0] = -s[0];
  return true;
}

IntervalIntegratorOptions scheme(IntervalScheme s, double T = 0.1, int substeps = 1) {
  IntervalIntegratorOptions o;
  o.scheme = s;
  o.sample_time = T;
  o.substeps = substeps;
  return o;
}

TEST(IntervalIntegrator, EverySchemeSolvesADecay) {
  for (IntervalScheme s : {IntervalScheme::kRk4, IntervalScheme::kDopri5, IntervalScheme::kCvode}) {
    IntervalIntegrator integrator(1, decay, scheme(s));
    std::vector<double> x{1.0};
    for (int k = 0; k < 10; ++k) {
      ASSERT_TRUE(integrator.integrate(0.1 * k, 0.1 * (k + 1), x)) << to_string(s);
    }
    // RK4 at h = 0.1: global error ~ h⁴/120 · t e^{−t} ≈ 3e-7; the adaptive ones at 1e-10
    // tolerance.
    EXPECT_NEAR(x[0], std::exp(-1.0), s == IntervalScheme::kRk4 ? 1e-6 : 1e-8) << to_string(s);
    EXPECT_GT(std::abs(x[0] - std::exp(-1.0)), 0.0) << to_string(s);  // computed, not copied
  }
}

TEST(IntervalIntegrator, Rk4KeepsItsStepLengthAcrossSeveralIntervals) {
  // One call over three sample times takes three steps: the same answer as three calls.
  IntervalIntegrator integrator(1, decay, scheme(IntervalScheme::kRk4, 0.1, 2));
  std::vector<double> once{1.0}, thrice{1.0};
  ASSERT_TRUE(integrator.integrate(0.0, 0.3, once));
  for (int k = 0; k < 3; ++k) ASSERT_TRUE(integrator.integrate(0.1 * k, 0.1 * (k + 1), thrice));
  EXPECT_NEAR(once[0], thrice[0], 1e-15);
}

TEST(IntervalIntegrator, ANonFiniteRightHandSideAbandonsTheInterval) {
  int calls = 0;
  const auto broken_after = [&calls](double, const double* s, double* ds) {
    ds[0] = -s[0];
    return ++calls < 3;
  };
  for (IntervalScheme s : {IntervalScheme::kRk4, IntervalScheme::kDopri5, IntervalScheme::kCvode}) {
    calls = 0;
    IntervalIntegrator integrator(1, broken_after, scheme(s));
    std::vector<double> x{1.0};
    std::string why;
    EXPECT_FALSE(integrator.integrate(0.0, 0.1, x, &why)) << to_string(s);
    if (s == IntervalScheme::kRk4) {
      EXPECT_EQ(calls, 3);  // stopped at the first refusal
    }
    if (s == IntervalScheme::kCvode) {
      EXPECT_NE(why.find("CVODE failed"), std::string::npos) << why;
    }
  }
}

TEST(IntervalIntegrator, OptionsAreChecked) {
  EXPECT_EQ(
      test::message_of([] { IntervalIntegrator(1, decay, scheme(IntervalScheme::kRk4, 0.0)); }),
      "IntervalIntegratorOptions::sample_time must be finite and > 0 (got 0)");
  EXPECT_EQ(
      test::message_of([] { IntervalIntegrator(1, decay, scheme(IntervalScheme::kRk4, 0.1, 0)); }),
      "IntervalIntegratorOptions::substeps must be >= 1 (got 0)");
  IntervalIntegratorOptions o = scheme(IntervalScheme::kDopri5);
  o.relative_tolerance = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(test::message_of([&] { IntervalIntegrator(1, decay, o); }),
            "IntervalIntegratorOptions::relative_tolerance must be finite and > 0 (got nan)");
  EXPECT_THROW(IntervalIntegrator(-1, decay, scheme(IntervalScheme::kRk4)), InvalidInput);
  std::vector<double> nothing;  // a state of size 0 (a PI bank of signals only): nothing to do
  EXPECT_TRUE(IntervalIntegrator(0, decay, scheme(IntervalScheme::kRk4)).integrate(0, 1, nothing));
}

// ---- the sampled-data rules -----------------------------------------------------------------

using Clock = SampledData<1, 1>;

TEST(SampledData, HoldStartIntegrateRejectInOnePlace) {
  Clock clock(1, 1, 0.5);
  ObserverStep step;
  const Eigen::VectorXd u = Eigen::VectorXd::Constant(1, 2.0),
                        y0 = Eigen::VectorXd::Constant(1, 1.0);
  EXPECT_EQ(clock.receive("obs", 0, 0.0, y0, u, step), Clock::kStart);
  EXPECT_EQ(clock.time(), 0.0);
  clock.accept();
  // A missing y: held, said in the step; the input of that sample is not taken either.
  EXPECT_EQ(clock.receive("obs", 1, 0.5, Eigen::VectorXd::Constant(1, NAN),
                          Eigen::VectorXd::Constant(1, 9.0), step),
            Clock::kHold);
  EXPECT_TRUE(step.measurement_missing);
  // A non-finite u: held, a failure naming u and t.
  EXPECT_EQ(clock.receive("obs", 2, 1.0, y0, Eigen::VectorXd::Constant(1, INFINITY), step),
            Clock::kHold);
  EXPECT_EQ(step.failure, "non_finite");
  EXPECT_NE(step.failure_message.find("obs: u_k is not finite at t = 1"), std::string::npos)
      << step.failure_message;
  // The next good sample integrates from the last taken one, across the gap, with u_0 held.
  EXPECT_EQ(clock.receive("obs", 3, 1.5, Eigen::VectorXd::Constant(1, 4.0),
                          Eigen::VectorXd::Constant(1, 5.0), step),
            Clock::kIntegrate);
  EXPECT_TRUE(step.failure.empty());
  EXPECT_EQ(clock.last_time(), 0.0);
  EXPECT_EQ(clock.time(), 1.5);
  EXPECT_EQ(clock.held_input()[0], 2.0);
  EXPECT_NEAR(clock.output_at(0.75)[0], 2.5, 1e-15);  // through (0, 1) and (1.5, 4)
  // Rejected: forgotten as if missing, the interpolation too.
  clock.reject(step, "obs: went wrong");
  EXPECT_EQ(step.failure, "non_finite");
  EXPECT_EQ(step.failure_message, "obs: went wrong");
  EXPECT_NEAR(clock.output_at(0.75)[0], 1.0, 1e-15);  // the one sample left
  EXPECT_EQ(clock.receive("obs", 4, 2.0, Eigen::VectorXd::Constant(1, 3.0),
                          Eigen::VectorXd::Constant(1, 7.0), step),
            Clock::kIntegrate);
  EXPECT_EQ(clock.last_time(), 0.0);
  EXPECT_EQ(clock.held_input()[0], 2.0);  // u_0 over [t_0, t_4]: the rejected u_3 never held
  clock.accept();
  EXPECT_EQ(clock.last_time(), 2.0);
  EXPECT_EQ(clock.held_input()[0], 7.0);  // u_4, for the next interval
  clock.reset();  // k = 0 again after a reset is a new start, not an order error
  EXPECT_EQ(clock.receive("obs", 0, 0.0, y0, u, step), Clock::kStart);
}

TEST(SampledData, SizesAndOrderAreErrors) {
  Clock clock(1, 1, 0.5);
  ObserverStep step;
  const Eigen::VectorXd one = Eigen::VectorXd::Constant(1, 1.0);
  EXPECT_EQ(
      test::message_of([&] { clock.receive("obs", 0, 0.0, Eigen::VectorXd::Zero(2), one, step); }),
      "obs: sample k = 0 has y of size 2 and u of size 1; the observer takes sizes 1 and 1");
  ASSERT_EQ(clock.receive("obs", 3, 1.5, one, one, step), Clock::kStart);
  clock.accept();
  EXPECT_NE(test::message_of([&] {
              clock.receive("obs", 3, 1.5, one, one, step);
            }).find("obs: sample k = 3 does not come after the last one"),
            std::string::npos);
  EXPECT_EQ(clock.receive("obs", 4, 2.0, one, one, step), Clock::kIntegrate);  // the clock goes on
}

// Samples placed by time on t_0 + m·T: t_0 the first sample's time (whatever its k), the grid
// time returned (not the rounded one given), skipped points a gap; off-grid, repeated,
// non-finite and too-large times refused with what and where.
TEST(UniformGrid, PlacesSamplesByTheirTime) {
  UniformGrid grid(0.1);
  ObserverStep step;
  std::optional<GridPoint> p = grid.place("obs", 3, 100.3, step);
  ASSERT_TRUE(p.has_value());
  EXPECT_EQ(p->index, 0);
  EXPECT_EQ(p->time, 100.3);
  p = grid.place("obs", 4, 100.4 + 1e-9, step);  // recorded rounding: on the grid
  ASSERT_TRUE(p.has_value());
  EXPECT_EQ(p->index, 1);
  EXPECT_EQ(p->time, 100.3 + 1 * 0.1);
  p = grid.place("obs", 5, 100.7, step);  // three points later: a gap, not an error
  ASSERT_TRUE(p.has_value());
  EXPECT_EQ(p->index, 4);
  EXPECT_FALSE(grid.place("obs", 6, 100.72, step).has_value());
  EXPECT_EQ(step.failure, "non_uniform");
  EXPECT_NE(step.failure_message.find("obs: sample k = 6 at t = 100.72 (T = 0.1)"),
            std::string::npos)
      << step.failure_message;
  EXPECT_NE(step.failure_message.find("nearest grid time 100.7"), std::string::npos)
      << step.failure_message;
  EXPECT_FALSE(grid.place("obs", 7, 100.7, step).has_value());  // that time again
  EXPECT_NE(step.failure_message.find("does not come after"), std::string::npos)
      << step.failure_message;
  for (const double bad : {NAN, INFINITY, -INFINITY}) {
    EXPECT_FALSE(grid.place("obs", 8, bad, step).has_value());
    EXPECT_EQ(step.failure, "non_finite");
  }
  EXPECT_FALSE(grid.place("obs", 9, 1e300, step).has_value());  // its rounding spans the grid
  EXPECT_EQ(step.failure, "non_uniform");
  EXPECT_NE(step.failure_message.find("too large"), std::string::npos) << step.failure_message;
  EXPECT_EQ(grid.place("obs", 10, 100.8, step)->index, 5);  // the refusals placed nothing
  grid.reset();                                             // a new origin
  EXPECT_EQ(grid.place("obs", 0, -5.0, step)->time, -5.0);
}

// A held sample has come (its k again is out of order, before any start too); one refused for
// its time has not, and may come again with the right time.
TEST(SampledData, AHeldSampleHasComeARefusedTimeMayComeAgain) {
  Clock clock(1, 1, 0.5);
  ObserverStep step;
  const Eigen::VectorXd one = Eigen::VectorXd::Constant(1, 1.0),
                        missing = Eigen::VectorXd::Constant(1, NAN);
  EXPECT_EQ(clock.receive("obs", 0, 0.0, missing, one, step), Clock::kHold);
  EXPECT_THROW(clock.receive("obs", 0, 0.0, one, one, step), InvalidInput);
  EXPECT_EQ(clock.receive("obs", 1, 0.6, one, one, step), Clock::kHold);
  EXPECT_EQ(step.failure, "non_uniform");
  EXPECT_EQ(clock.receive("obs", 1, 0.5, one, one, step), Clock::kStart);
  EXPECT_EQ(clock.time(), 0.5);
}

TEST(SampledData, AnOffGridTimeIsHeldAndTheNextOneGoesOn) {
  Clock clock(1, 1, 0.5);
  ObserverStep step;
  const Eigen::VectorXd one = Eigen::VectorXd::Constant(1, 1.0);
  ASSERT_EQ(clock.receive("obs", 0, 0.0, one, one, step), Clock::kStart);
  clock.accept();
  EXPECT_EQ(clock.receive("obs", 1, 0.7, one, one, step), Clock::kHold);
  EXPECT_EQ(step.failure, "non_uniform");
  EXPECT_EQ(clock.receive("obs", 2, 1.0, one, one, step), Clock::kIntegrate);
  EXPECT_TRUE(step.failure.empty());
  EXPECT_EQ(clock.last_time(), 0.0);  // across the refused sample
  EXPECT_EQ(clock.time(), 1.0);
}

// The PI bank now follows the same rule as the MVT and high-gain observers after a failed step:
// the sample is dropped as if missing and the next one integrates from the last good state.
TEST(SampledData, APiBankResumesFromTheLastGoodStateAfterAFailedStep) {
  PiBank bank(1, 0);
  const auto y = bank.output(0);
  const auto inv = bank.add_signal("inverse", [y](const PiBank::Values& v) { return 1.0 / v[y]; });
  const auto eta = bank.add_pi("eta", {.measured = inv, .gains = {8, 15}});
  const PiBankOptions options{.name = "pi", .estimate = {eta.eta}, .sample_time = 0.5};
  PiBankObserver failing(bank, options), reference(bank, options);
  const auto sample = [](double v) { return Eigen::VectorXd::Constant(1, v); };
  for (PiBankObserver* o : {&failing, &reference}) {
    o->step(0, 0.0, sample(1.0), {});
    o->step(1, 0.5, sample(0.5), {});
  }
  EXPECT_EQ(failing.step(2, 1.0, sample(-0.5), {}).failure, "non_finite");   // y = 0 at t = 0.75
  EXPECT_TRUE(reference.step(2, 1.0, sample(NAN), {}).measurement_missing);  // the same, missing
  const Eigen::VectorXd after = failing.step(3, 1.5, sample(0.6), {}).estimate;
  EXPECT_EQ(after, reference.step(3, 1.5, sample(0.6), {}).estimate);
  EXPECT_TRUE(after.allFinite());
}

// A bank of signals only has nothing to integrate; a signal that leaves its domain is still
// caught at the sample, not published.
TEST(SampledData, ABankOfSignalsOnlyStillReportsANonFiniteSignal) {
  PiBank bank(1, 0);
  const auto y = bank.output(0);
  const auto inv = bank.add_signal("inverse", [y](const PiBank::Values& v) { return 1.0 / v[y]; });
  ASSERT_EQ(bank.state_size(), 0);
  PiBankObserver observer(bank, {.name = "pi", .estimate = {inv}, .sample_time = 0.5});
  const auto sample = [](double v) { return Eigen::VectorXd::Constant(1, v); };
  EXPECT_EQ(observer.step(0, 0.0, sample(2.0), {}).estimate[0], 0.5);
  const ObserverStep& bad = observer.step(1, 0.5, sample(0.0), {});
  EXPECT_EQ(bad.failure, "non_finite");
  EXPECT_NE(bad.failure_message.find("signal 'inverse' is not finite at t = 0.5"),
            std::string::npos)
      << bad.failure_message;
  EXPECT_EQ(bad.estimate[0], 0.5);  // the last good one
  EXPECT_EQ(observer.step(2, 1.0, sample(4.0), {}).estimate[0], 0.25);
}

// Hostile values: an integrator at 1e308 with rate 1e308 overflows within the first interval.
// The step is refused with a failure naming the signal, the published estimate stays the last
// finite one, and the bank keeps refusing (its state cannot get back) instead of publishing inf.
TEST(SampledData, AnOverflowingBankStateIsRefusedNotPublished) {
  PiBank bank(1, 0);
  const auto blow = bank.add_integrator(
      "blow", [](const PiBank::Values& v) { return 1e308 + 0.0 * v.time(); }, 1e308);
  PiBankObserver observer(bank, {.name = "pi", .estimate = {blow}, .sample_time = 1.0});
  const auto sample = [](double v) { return Eigen::VectorXd::Constant(1, v); };
  EXPECT_EQ(observer.step(0, 0.0, sample(1.0), {}).estimate[0], 1e308);
  for (long k = 1; k < 4; ++k) {
    const ObserverStep& s = observer.step(k, static_cast<double>(k), sample(1.0), {});
    EXPECT_EQ(s.failure, "non_finite") << k;
    // Each later sample integrates from the last good state (t = 0), whose first RK4 step
    // already overflows at its end, t = 1.
    EXPECT_EQ(s.failure_message,
              "pi: signal 'blow' is not finite at t = 1; kept the estimate of t = 0");
    EXPECT_EQ(s.estimate[0], 1e308) << k;
  }
}

}  // namespace
}  // namespace nlobs
