// The periodic errors-in-variables estimator (periodic_frf.h) on simulated measurements of
// the reference motor (R 0.5 ohm, L 2 mH, Rp 0.51 ohm, f0 390 Hz, Q 50): exact on noise-free
// data, honest sigma (Monte Carlo), transient periods dropped, and every invalid measurement
// reported as not usable with its reason.
#include "analysis/signal/periodic_frf.h"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <limits>
#include <numbers>

#include "analysis/bench/fit_bench.h"
#include "analysis/model/motor_model.h"
#include "analysis/signal/multisine.h"
#include "analysis/sim/steady_state.h"

namespace eol::analysis {
namespace {

#define EXPECT_CONTAINS(haystack, needle) \
  EXPECT_PRED_FORMAT2(::testing::IsSubstring, needle, haystack)

const MotionalImpedance kMotor{0.5, 2.0e-3, 0.51, 390.0, 50.0};

// 10 Hz lines from 200 to 800 Hz at 8 kHz: 800-sample periods keep the Monte Carlo fast.
Excitation ShortExcitation() {
  MultisineOptions o;
  o.line_spacing_hz = 10.0;
  return DesignMultisine(o);
}

struct Errors {
  double mean_normalised = 0.0;  // mean over lines and runs of |dZ|^2 / sigma^2
  double ratio_of_means = 0.0;   // mean |dZ|^2 / mean sigma^2
};

Errors MonteCarlo(std::size_t periods, std::size_t smoothing, int runs, double noise_scale) {
  const Excitation e = ShortExcitation();
  PeriodicFrfOptions o;
  o.noise_smoothing_lines = smoothing;
  double norm_sum = 0.0, err2 = 0.0, sig2 = 0.0;
  long count = 0;
  for (int r = 0; r < runs; ++r) {
    const Recording rec = SimulatePeriodicRecording(kMotor, e, periods, 2e-3 * noise_scale,
                                                    1e-3 * noise_scale, 100 + r);
    const FrfSummary s = EstimatePeriodicFrf(rec, e.lines, o);
    EXPECT_TRUE(s.usable) << s.message;
    if (!s.usable) continue;
    for (std::size_t k = 0; k < s.frf.size(); ++k) {
      const double d2 = std::norm(s.frf.value[k] - kMotor.At(s.frf.freq_hz[k]));
      norm_sum += d2 / (s.frf.sigma[k] * s.frf.sigma[k]);
      err2 += d2;
      sig2 += s.frf.sigma[k] * s.frf.sigma[k];
      ++count;
    }
  }
  return {norm_sum / static_cast<double>(count), err2 / sig2};
}

TEST(PeriodicFrfTest, ExactOnNoiseFreeData) {
  const Excitation e = ShortExcitation();
  const Recording rec = SimulatePeriodicRecording(kMotor, e, 5, 0.0, 0.0, 1);
  const FrfSummary s = EstimatePeriodicFrf(rec, e.lines, PeriodicFrfOptions{});
  ASSERT_TRUE(s.usable) << s.message;
  EXPECT_EQ(s.frf.method, "periodic-eiv");
  EXPECT_EQ(s.frf.quantity, Quantity::kImpedanceOhm);
  EXPECT_EQ(s.periods_used, 4u);
  EXPECT_EQ(s.periods_dropped, 1u);
  ASSERT_EQ(s.frf.size(), e.lines.size());
  for (std::size_t k = 0; k < s.frf.size(); ++k) {
    const std::complex<double> z = kMotor.At(s.frf.freq_hz[k]);
    EXPECT_NEAR(std::abs(s.frf.value[k] - z), 0.0, 1e-10 * std::abs(z)) << s.frf.freq_hz[k];
    EXPECT_LT(s.frf.sigma[k], 1e-9 * std::abs(z));
  }
}

// Honest sigma: the squared error averages the reported sigma^2. The mean of the ratio
// |dZ|^2 / sigma_hat^2 carries the small F-law excess nu / (nu - 2) of an estimated variance
// (nu = 2 (P - 1)(2 h + 1) real degrees of freedom: 1.03 at P = 4, h = 5; 1.06 at P = 19, h = 0).
TEST(PeriodicFrfTest, SigmaIsHonestRecipePeriodsPooled) {
  const Errors e = MonteCarlo(5, 5, 150, 10.0);
  std::printf("P = 4, h = 5: mean |dZ|^2/sigma^2 = %.3f, mean |dZ|^2 / mean sigma^2 = %.3f\n",
              e.mean_normalised, e.ratio_of_means);
  EXPECT_NEAR(e.ratio_of_means, 1.0, 0.06);
  EXPECT_NEAR(e.mean_normalised, 66.0 / 64.0, 0.07);
}

TEST(PeriodicFrfTest, SigmaIsHonestManyPeriodsPerLine) {
  const Errors e = MonteCarlo(20, 0, 60, 10.0);
  std::printf("P = 19, h = 0: mean |dZ|^2/sigma^2 = %.3f, mean |dZ|^2 / mean sigma^2 = %.3f\n",
              e.mean_normalised, e.ratio_of_means);
  EXPECT_NEAR(e.ratio_of_means, 1.0, 0.06);
  EXPECT_NEAR(e.mean_normalised, 36.0 / 34.0, 0.07);
}

// A decaying transient (the mode ringing after switch-on) in the first two periods: the first
// period is always dropped, the second is detected and dropped too. Kept, it biases Z.
TEST(PeriodicFrfTest, TransientPeriodsDetectedAndDropped) {
  const Excitation e = ShortExcitation();
  Recording rec = SimulatePeriodicRecording(kMotor, e, 8, 2e-3, 1e-3, 5);
  const double tau_s = 0.05;  // e^-2 after one 0.1 s period; cut off after the second
  for (std::size_t t = 0; t < 2 * e.period_samples; ++t) {
    const double ts = static_cast<double>(t) / rec.sample_rate_hz;
    rec.current_a[t] += 0.3 * std::exp(-ts / tau_s) * std::sin(2.0 * std::numbers::pi * 390.0 * ts);
  }
  const FrfSummary s = EstimatePeriodicFrf(rec, e.lines, PeriodicFrfOptions{});
  ASSERT_TRUE(s.usable) << s.message;
  EXPECT_EQ(s.periods_dropped, 2u);
  EXPECT_EQ(s.periods_used, 6u);
  EXPECT_CONTAINS(s.message, "2 dropped");
  double worst = 0.0;
  for (std::size_t k = 0; k < s.frf.size(); ++k)
    worst =
        std::max(worst, std::abs(s.frf.value[k] - kMotor.At(s.frf.freq_hz[k])) / s.frf.sigma[k]);
  EXPECT_LT(worst, 5.0);

  PeriodicFrfOptions blind;
  blind.transient_threshold = 1e12;  // never drops more than the first period
  const FrfSummary b = EstimatePeriodicFrf(rec, e.lines, blind);
  ASSERT_TRUE(b.usable) << b.message;
  EXPECT_EQ(b.periods_dropped, 1u);
  double worst_blind = 0.0;
  for (std::size_t k = 0; k < b.frf.size(); ++k)
    worst_blind = std::max(worst_blind, std::abs(b.frf.value[k] - kMotor.At(b.frf.freq_hz[k])) /
                                            std::abs(kMotor.At(b.frf.freq_hz[k])));
  double worst_rel = 0.0;
  for (std::size_t k = 0; k < s.frf.size(); ++k)
    worst_rel = std::max(worst_rel, std::abs(s.frf.value[k] - kMotor.At(s.frf.freq_hz[k])) /
                                        std::abs(kMotor.At(s.frf.freq_hz[k])));
  EXPECT_GT(worst_blind, 3.0 * worst_rel);
}

TEST(PeriodicFrfTest, NanSampleIsNotUsable) {
  const Excitation e = ShortExcitation();
  Recording rec = SimulatePeriodicRecording(kMotor, e, 5, 2e-3, 1e-3, 1);
  rec.voltage_v[1234] = std::numeric_limits<double>::quiet_NaN();
  const FrfSummary s = EstimatePeriodicFrf(rec, e.lines, PeriodicFrfOptions{});
  EXPECT_FALSE(s.usable);
  EXPECT_CONTAINS(s.message, "voltage sample 1234 is not finite");
}

TEST(PeriodicFrfTest, ClippingIsNotUsable) {
  const Excitation e = ShortExcitation();
  Recording rec = SimulatePeriodicRecording(kMotor, e, 5, 2e-3, 1e-3, 1);
  rec.voltage_full_scale_v = 10.0;
  rec.current_full_scale_a = 0.05;  // below the current's peak
  for (double& i : rec.current_a) i = std::clamp(i, -0.05, 0.05);
  const FrfSummary s = EstimatePeriodicFrf(rec, e.lines, PeriodicFrfOptions{});
  EXPECT_FALSE(s.usable);
  EXPECT_TRUE(s.clipped);
  EXPECT_EQ(s.message.rfind("current clipped at 0.05 A: ", 0), 0u) << s.message;
  EXPECT_CONTAINS(s.message, "of the converter's full scale; lower the excitation level");
}

TEST(PeriodicFrfTest, MissingCurrentRelayOpenIsNotUsable) {
  const Excitation e = ShortExcitation();
  Recording rec = SimulatePeriodicRecording(kMotor, e, 5, 2e-3, 1e-3, 1);
  const Recording open = SimulatePeriodicRecording(kMotor, e, 5, 2e-3, 1e-3, 2);
  for (std::size_t t = 0; t < rec.current_a.size(); ++t)  // noise only: no current flows
    rec.current_a[t] = open.current_a[t] - rec.current_a[t];
  const FrfSummary s = EstimatePeriodicFrf(rec, e.lines, PeriodicFrfOptions{});
  EXPECT_FALSE(s.usable);
  EXPECT_CONTAINS(s.message, "no signal: ");
  EXPECT_CONTAINS(s.message, "excited lines have no current above the noise");
}

TEST(PeriodicFrfTest, TooFewPeriodsIsNotUsable) {
  const Excitation e = ShortExcitation();
  const Recording rec = SimulatePeriodicRecording(kMotor, e, 2, 2e-3, 1e-3, 1);
  const FrfSummary s = EstimatePeriodicFrf(rec, e.lines, PeriodicFrfOptions{});
  EXPECT_FALSE(s.usable);
  EXPECT_CONTAINS(s.message, "only 2 whole periods recorded; need 3");
}

TEST(PeriodicFrfTest, InvalidOptionsAreReported) {
  const Excitation e = ShortExcitation();
  const Recording rec = SimulatePeriodicRecording(kMotor, e, 5, 2e-3, 1e-3, 1);
  PeriodicFrfOptions o;
  o.min_periods = 1;
  const FrfSummary s = EstimatePeriodicFrf(rec, e.lines, o);
  EXPECT_FALSE(s.usable);
  EXPECT_CONTAINS(s.message, "invalid options: min_periods must be at least 2");
}

// Any two channels: y = G x with a known G, transfer j w Y / X as a mobility.
TEST(PeriodicTransferTest, TwoChannelsWithDerivative) {
  const Excitation e = ShortExcitation();
  // "Angle per current" of a damped mass: G = 1 / (s (J s + b)).
  const auto g = [](double f) {
    const std::complex<double> s(0.0, 2.0 * std::numbers::pi * f);
    return 1.0 / (s * (1e-3 * s + 0.2));
  };
  const std::vector<double> x = e.Repeat(4);
  const std::vector<double> y_period =
      SteadyStateCurrent([&](double f) { return 1.0 / g(f); }, e.period_v, e.sample_rate_hz);
  std::vector<double> y(x.size());
  for (std::size_t t = 0; t < y.size(); ++t) y[t] = y_period[t % e.period_samples];
  ChannelPair p;
  p.sample_rate_hz = e.sample_rate_hz;
  p.period_samples = e.period_samples;
  p.x = x;
  p.y = y;
  p.x_name = "iq";
  p.y_name = "theta";
  p.quantity = Quantity::kMobility;
  p.output_jw_power = 1;
  const FrfSummary s = EstimatePeriodicTransfer(p, e.lines, PeriodicFrfOptions{});
  ASSERT_TRUE(s.usable) << s.message;
  EXPECT_EQ(s.frf.quantity, Quantity::kMobility);
  for (std::size_t k = 0; k < s.frf.size(); ++k) {
    const double f = s.frf.freq_hz[k];
    const std::complex<double> want = std::complex<double>(0.0, 2.0 * std::numbers::pi * f) * g(f);
    EXPECT_NEAR(std::abs(s.frf.value[k] - want), 0.0, 1e-9 * std::abs(want)) << f;
  }
  std::vector<double> bad = y;
  bad[7] = std::numeric_limits<double>::infinity();
  p.y = bad;
  const FrfSummary b = EstimatePeriodicTransfer(p, e.lines, PeriodicFrfOptions{});
  EXPECT_FALSE(b.usable);
  EXPECT_CONTAINS(b.message, "theta sample 7 is not finite");
}

}  // namespace
}  // namespace eol::analysis
