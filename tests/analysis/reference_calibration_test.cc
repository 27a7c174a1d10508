// The reference-resistor calibration fit (analysis/signal/reference_calibration.h): known
// gain and delay in a noisy synthetic Z(f) = R_ref g exp(j w tau) are recovered within three
// sigma for every seed, the sigmas are honest (the spread over seeds matches them), a
// periodic fractional delay is exact, and bad inputs give usable == false with the reason.
#include "analysis/signal/reference_calibration.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

namespace eol::analysis {
namespace {

Frf Synthetic(double r_ohm, double gain, double delay_s, double sigma_ohm, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, sigma_ohm / std::sqrt(2.0));
  Frf z;
  for (double f = 200.0; f <= 2000.0; f += 10.0) {
    z.freq_hz.push_back(f);
    const double w = 2.0 * std::numbers::pi * f;
    z.value.push_back(r_ohm * gain * std::polar(1.0, w * delay_s) +
                      std::complex<double>(n(rng), n(rng)));
    z.sigma.push_back(sigma_ohm);
  }
  return z;
}

TEST(ReferenceCalibration, RecoversGainAndDelayWithinThreeSigma) {
  ReferenceCalibrationOptions o;
  o.reference_ohm = 2.2;
  double sum_z2_gain = 0.0, sum_z2_delay = 0.0;
  const int runs = 40;
  for (int seed = 1; seed <= runs; ++seed) {
    const ReferenceCalibrationSummary s =
        EstimateReferenceCalibration(Synthetic(2.2, 1.03, 20e-6, 0.01, seed), o);
    ASSERT_TRUE(s.usable) << s.message;
    EXPECT_NEAR(s.gain, 1.03, 3 * s.gain_sigma) << "seed " << seed;
    EXPECT_NEAR(s.delay_s, 20e-6, 3 * s.delay_sigma_s) << "seed " << seed;
    EXPECT_LT(s.gain_sigma, 1e-3);
    EXPECT_LT(s.delay_sigma_s, 1e-6);
    sum_z2_gain += std::pow((s.gain - 1.03) / s.gain_sigma, 2);
    sum_z2_delay += std::pow((s.delay_s - 20e-6) / s.delay_sigma_s, 2);
  }
  // Honest sigmas: the normalised errors have unit variance (40 runs: 0.55..1.6 at ~99 %).
  EXPECT_GT(sum_z2_gain / runs, 0.5);
  EXPECT_LT(sum_z2_gain / runs, 1.7);
  EXPECT_GT(sum_z2_delay / runs, 0.5);
  EXPECT_LT(sum_z2_delay / runs, 1.7);
}

TEST(ReferenceCalibration, NegativeDelayAndNoSigma) {
  ReferenceCalibrationOptions o;
  o.reference_ohm = 1.0;
  Frf z = Synthetic(1.0, 0.97, -35e-6, 0.0, 1);
  z.sigma.clear();
  const ReferenceCalibrationSummary s = EstimateReferenceCalibration(z, o);
  ASSERT_TRUE(s.usable) << s.message;
  EXPECT_NEAR(s.gain, 0.97, 1e-12);
  EXPECT_NEAR(s.delay_s, -35e-6, 1e-15);
}

TEST(ReferenceCalibration, WrongReferenceOrTooFewLinesIsNotUsable) {
  ReferenceCalibrationOptions o;
  o.reference_ohm = 10.0;  // the resistor was 1 ohm: a gain of 0.1 is wiring, not calibration
  ReferenceCalibrationSummary s = EstimateReferenceCalibration(Synthetic(1.0, 1.0, 0, 1e-3, 1), o);
  EXPECT_FALSE(s.usable);
  EXPECT_NE(s.message.find("wrong reference_ohm"), std::string::npos) << s.message;

  o.reference_ohm = 0.0;
  s = EstimateReferenceCalibration(Synthetic(1.0, 1.0, 0, 1e-3, 1), o);
  EXPECT_FALSE(s.usable);
  EXPECT_NE(s.message.find("reference_ohm must be positive"), std::string::npos) << s.message;

  o.reference_ohm = 1.0;
  Frf two = Synthetic(1.0, 1.0, 0, 1e-3, 1);
  two.freq_hz.resize(2);
  two.value.resize(2);
  two.sigma.resize(2);
  s = EstimateReferenceCalibration(two, o);
  EXPECT_FALSE(s.usable);
  EXPECT_NE(s.message.find("at least 3 lines"), std::string::npos) << s.message;
}

TEST(DelayPeriodic, FractionalDelayOfAPeriodicSignalIsExact) {
  const double fs = 8000.0;
  const std::size_t n = 800;
  std::vector<double> x(n);
  for (std::size_t t = 0; t < n; ++t)
    x[t] = std::sin(2 * std::numbers::pi * 250.0 * static_cast<double>(t) / fs) +
           0.5 * std::cos(2 * std::numbers::pi * 730.0 * static_cast<double>(t) / fs);
  std::vector<double> y = x;
  const double d = 20e-6;  // 0.16 samples
  DelayPeriodic(y, d, fs);
  for (std::size_t t = 0; t < n; ++t) {
    const double tt = static_cast<double>(t) / fs - d;
    EXPECT_NEAR(y[t],
                std::sin(2 * std::numbers::pi * 250.0 * tt) +
                    0.5 * std::cos(2 * std::numbers::pi * 730.0 * tt),
                1e-12);
  }
  DelayPeriodic(y, -d, fs);
  for (std::size_t t = 0; t < n; ++t) EXPECT_NEAR(y[t], x[t], 1e-12);
}

}  // namespace
}  // namespace eol::analysis
