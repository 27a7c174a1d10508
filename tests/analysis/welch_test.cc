// Welch H1 / H2 with coherence (welch.h) on a known linear system driven by Gaussian noise:
// y = h * x (a short FIR, H(f) = sum_d h_d exp(-j w d / fs)) plus noise on either channel.
#include "analysis/signal/welch.h"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <random>

namespace eol::analysis {
namespace {

#define EXPECT_CONTAINS(haystack, needle) \
  EXPECT_PRED_FORMAT2(::testing::IsSubstring, needle, haystack)

constexpr double kFs = 1000.0;
const std::vector<double> kFir = {0.5, 0.3, 0.0, -0.2};

std::complex<double> FirResponse(double f_hz) {
  std::complex<double> h = 0.0;
  for (std::size_t d = 0; d < kFir.size(); ++d)
    h += kFir[d] * std::polar(1.0, -2.0 * std::numbers::pi * f_hz * static_cast<double>(d) / kFs);
  return h;
}

struct Signals {
  std::vector<double> x_true, x, y;
};

// White Gaussian input of unit variance through the FIR; noise of the given rms added to the
// measured input and output.
Signals Simulate(std::size_t n, double input_noise, double output_noise, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  Signals s;
  s.x_true.resize(n);
  for (double& v : s.x_true) v = g(rng);
  s.x = s.x_true;
  s.y.assign(n, 0.0);
  for (std::size_t t = 0; t < n; ++t) {
    for (std::size_t d = 0; d < kFir.size() && d <= t; ++d) s.y[t] += kFir[d] * s.x_true[t - d];
    s.y[t] += output_noise * g(rng);
    s.x[t] += input_noise * g(rng);
  }
  return s;
}

ChannelPair Pair(const Signals& s) {
  ChannelPair p;
  p.sample_rate_hz = kFs;
  p.x = s.x;
  p.y = s.y;
  p.x_name = "force";
  p.y_name = "response";
  p.quantity = Quantity::kMobility;
  return p;
}

WelchOptions Options(WelchEstimator e = WelchEstimator::kH1) {
  WelchOptions o;
  o.segment_samples = 512;
  o.overlap = 0.5;
  o.estimator = e;
  o.f_lo_hz = 20.0;
  o.f_hi_hz = 400.0;
  return o;
}

TEST(WelchTest, NoiseFreeSystemIsRecovered) {
  const Signals s = Simulate(200000, 0.0, 0.0, 1);
  const WelchSummary w = EstimateWelchFrf(Pair(s), Options());
  ASSERT_TRUE(w.usable) << w.message;
  EXPECT_EQ(w.frf.method, "welch-h1");
  EXPECT_EQ(w.frf.quantity, Quantity::kMobility);
  EXPECT_EQ(w.segments, (200000u - 512u) / 256u + 1u);
  EXPECT_NEAR(w.effective_averages / static_cast<double>(w.segments), 1.0 / 1.056, 0.01);
  ASSERT_EQ(w.coherence.size(), w.frf.size());
  EXPECT_DOUBLE_EQ(w.frf.freq_hz.front(), 1000.0 / 512.0 * 11.0);  // first bin >= 20 Hz
  for (std::size_t k = 0; k < w.frf.size(); ++k) {
    const std::complex<double> h = FirResponse(w.frf.freq_hz[k]);
    // Only the FIR's delay across segment edges separates H1 from H (a few 1e-3).
    EXPECT_NEAR(std::abs(w.frf.value[k] - h), 0.0, 1e-2 * std::abs(h)) << w.frf.freq_hz[k];
    EXPECT_GT(w.coherence[k], 0.99);
  }
}

// Input noise biases H1 low by Sxx / (Sxx + Snn); H2 is unbiased by it.
TEST(WelchTest, InputNoiseBiasesH1NotH2) {
  const double nin = 0.5;  // Snn / Sxx = 0.25
  const Signals s = Simulate(400000, nin, 0.0, 2);
  const WelchSummary h1 = EstimateWelchFrf(Pair(s), Options(WelchEstimator::kH1));
  const WelchSummary h2 = EstimateWelchFrf(Pair(s), Options(WelchEstimator::kH2));
  ASSERT_TRUE(h1.usable) << h1.message;
  ASSERT_TRUE(h2.usable) << h2.message;
  EXPECT_EQ(h2.frf.method, "welch-h2");
  double r1 = 0.0, r2 = 0.0;
  for (std::size_t k = 0; k < h1.frf.size(); ++k) {
    const std::complex<double> h = FirResponse(h1.frf.freq_hz[k]);
    r1 += std::abs(h1.frf.value[k]) / std::abs(h);
    r2 += std::abs(h2.frf.value[k]) / std::abs(h);
  }
  r1 /= static_cast<double>(h1.frf.size());
  r2 /= static_cast<double>(h2.frf.size());
  EXPECT_NEAR(r1, 1.0 / 1.25, 0.01);
  EXPECT_NEAR(r2, 1.0, 0.01);
}

// With output noise only, the coherence formula's sigma matches the scatter of H1.
TEST(WelchTest, SigmaFromCoherenceIsHonest) {
  double norm = 0.0, err2 = 0.0, sig2 = 0.0;
  long count = 0;
  for (int r = 0; r < 40; ++r) {
    const Signals s = Simulate(40000, 0.0, 0.4, 100 + r);
    const WelchSummary w = EstimateWelchFrf(Pair(s), Options());
    ASSERT_TRUE(w.usable) << w.message;
    for (std::size_t k = 0; k < w.frf.size(); ++k) {
      const double d2 = std::norm(w.frf.value[k] - FirResponse(w.frf.freq_hz[k]));
      norm += d2 / (w.frf.sigma[k] * w.frf.sigma[k]);
      err2 += d2;
      sig2 += w.frf.sigma[k] * w.frf.sigma[k];
      ++count;
    }
  }
  std::printf("Welch H1: mean |dH|^2/sigma^2 = %.3f, mean |dH|^2 / mean sigma^2 = %.3f\n",
              norm / count, err2 / sig2);
  EXPECT_NEAR(err2 / sig2, 1.0, 0.12);
  EXPECT_NEAR(norm / count, 1.0, 0.15);
}

TEST(WelchTest, UnrelatedOutputHasTooLowCoherence) {
  Signals s = Simulate(50000, 0.0, 0.0, 3);
  const Signals other = Simulate(50000, 0.0, 0.0, 4);
  s.y = other.y;  // the output does not come from this input
  const WelchSummary w = EstimateWelchFrf(Pair(s), Options());
  EXPECT_FALSE(w.usable);
  EXPECT_CONTAINS(w.message, "coherence too low: median ");
  EXPECT_CONTAINS(w.message, "the force does not explain the response");
  EXPECT_EQ(w.frf.size(), 0u);
}

TEST(WelchTest, InvalidDataIsReported) {
  const Signals good = Simulate(20000, 0.0, 0.1, 5);
  {
    Signals s = good;
    s.y[999] = std::numeric_limits<double>::quiet_NaN();
    const WelchSummary w = EstimateWelchFrf(Pair(s), Options());
    EXPECT_FALSE(w.usable);
    EXPECT_CONTAINS(w.message, "response sample 999 is not finite");
  }
  {
    ChannelPair p = Pair(good);
    p.x_full_scale = 2.0;  // a unit Gaussian passes 2 now and then
    const WelchSummary w = EstimateWelchFrf(p, Options());
    EXPECT_FALSE(w.usable);
    EXPECT_TRUE(w.clipped);
    EXPECT_EQ(w.message.rfind(p.x_name + " clipped at 2: ", 0), 0u) << w.message;
  }
  {
    Signals s = good;
    s.x.assign(s.x.size(), 0.25);  // relay open: nothing on the input
    const WelchSummary w = EstimateWelchFrf(Pair(s), Options());
    EXPECT_FALSE(w.usable);
    EXPECT_CONTAINS(w.message, "no signal: the force channel is constant");
  }
  {
    Signals s = Simulate(1500, 0.0, 0.1, 6);
    const WelchSummary w = EstimateWelchFrf(Pair(s), Options());
    EXPECT_FALSE(w.usable);
    EXPECT_CONTAINS(w.message, "record too short: 1500 samples give 4 segments of 512; need 8");
  }
  {
    WelchOptions o = Options();
    o.overlap = 1.0;
    const WelchSummary w = EstimateWelchFrf(Pair(good), o);
    EXPECT_FALSE(w.usable);
    EXPECT_CONTAINS(w.message, "invalid options: overlap must be in [0, 0.95]");
  }
}

}  // namespace
}  // namespace eol::analysis
