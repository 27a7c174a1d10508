// Clipping (analysis/signal/clipping.h): a channel at its stated full scale, or repeated at a
// rail when the range is unknown, is refused before any spectrum with the level and counts;
// a clean, quantised recording, a constant channel and a few codes of noise are not rails.
#include "analysis/signal/clipping.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "analysis/bench/fit_bench.h"
#include "analysis/signal/multisine.h"
#include "analysis/signal/periodic_frf.h"

namespace eol::analysis {
namespace {

#define EXPECT_CONTAINS(haystack, needle) \
  EXPECT_PRED_FORMAT2(::testing::IsSubstring, needle, haystack)

const MotionalImpedance kMotor{0.5, 2.0e-3, 0.51, 390.0, 50.0};

// The recipe's 1 Hz multisine, 5 periods, DAQ noise, 16-bit quantised to the full scales.
Recording Quantised(double v_fs, double i_fs, std::uint64_t seed) {
  const Excitation e = DesignMultisine(MultisineOptions{});
  Recording rec = SimulatePeriodicRecording(kMotor, e, 5, 2e-3, 1e-3, seed);
  for (auto [x, fs] : {std::pair{&rec.voltage_v, v_fs}, std::pair{&rec.current_a, i_fs}}) {
    const double lsb = fs / 32768.0;
    for (double& v : *x) v = std::clamp(std::round(v / lsb), -32768.0, 32767.0) * lsb;
  }
  return rec;
}

double PeakAbs(const std::vector<double>& x) {
  double p = 0.0;
  for (double v : x) p = std::max(p, std::abs(v));
  return p;
}

TEST(Clipping, CleanQuantisedRecordingIsNotClipped) {
  const Recording rec = Quantised(10.0, 2.0, 1);
  EXPECT_FALSE(FindClipping(rec.voltage_v, 0.0).clipped);
  EXPECT_FALSE(FindClipping(rec.current_a, 0.0).clipped);
  EXPECT_FALSE(FindClipping(rec.current_a, 2.0).clipped);
  const FrfSummary s = EstimatePeriodicFrf(rec, DesignMultisine({}).lines, {});
  EXPECT_TRUE(s.usable) << s.message;
  EXPECT_FALSE(s.clipped);
}

TEST(Clipping, CurrentAtARailIsFoundWithoutTheFullScale) {
  const Recording clean = Quantised(10.0, 2.0, 2);
  const double peak = PeakAbs(clean.current_a);
  const double i_fs = 0.6 * peak;  // the converter's range, unknown to the file
  const Recording rec = Quantised(10.0, i_fs, 2);
  const ChannelClipping c = FindClipping(rec.current_a, 0.0);
  ASSERT_TRUE(c.clipped);
  EXPECT_FALSE(c.at_full_scale);
  EXPECT_NEAR(std::abs(c.level), i_fs, i_fs / 16384.0);
  EXPECT_GE(c.longest_run, kMinRailRun);
  EXPECT_FALSE(FindClipping(rec.voltage_v, 0.0).clipped);
  const FrfSummary s = EstimatePeriodicFrf(rec, DesignMultisine({}).lines, {});
  EXPECT_FALSE(s.usable);
  EXPECT_TRUE(s.clipped);
  EXPECT_EQ(s.message.rfind("current clipped at ", 0), 0u) << s.message;
  EXPECT_CONTAINS(s.message, " A: ");
  EXPECT_CONTAINS(s.message, "a converter rail; lower the excitation level or raise the range");
}

TEST(Clipping, StatedFullScaleCountsEverySampleAtIt) {
  std::vector<double> x(1000);
  for (std::size_t k = 0; k < x.size(); ++k) x[k] = 1.5 * std::sin(0.05 * static_cast<double>(k));
  const ChannelClipping c = FindClipping(x, 1.5005);
  ASSERT_TRUE(c.clipped);
  EXPECT_TRUE(c.at_full_scale);
  EXPECT_EQ(c.level, 1.5005);
  EXPECT_GT(c.samples, 0u);
  EXPECT_EQ(ClippingMessage("voltage", "V", c, x.size())
                .rfind("voltage clipped at 1.5 V: 21 of 1000 samples at or beyond", 0),
            0u)
      << ClippingMessage("voltage", "V", c, x.size());
  EXPECT_FALSE(FindClipping(x, 2.0).clipped);  // a smooth peak passes its extreme once
}

TEST(Clipping, ConstantChannelsAndCoarseNoiseAreNotRails) {
  EXPECT_FALSE(FindClipping(std::vector<double>(5000, 0.25), 0.0).clipped);
  EXPECT_FALSE(FindClipping(std::vector<double>(5000, 0.0), 0.0).clipped);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<double> codes(40000);  // an open circuit: noise of a few codes
  for (double& v : codes) v = std::round(1.5 * n(rng)) * 6.1e-5;
  EXPECT_FALSE(FindClipping(codes, 0.0).clipped);
  std::vector<double> flat_top(40000);  // the same swing, clipped at +0.8 only
  for (std::size_t k = 0; k < flat_top.size(); ++k)
    flat_top[k] = std::min(0.8, std::sin(0.01 * static_cast<double>(k)));
  const ChannelClipping top = FindClipping(flat_top, 0.0);
  ASSERT_TRUE(top.clipped);
  EXPECT_EQ(top.level, 0.8);
  EXPECT_CONTAINS(ClippingMessage("current", "A", top, flat_top.size()),
                  "current clipped at 0.8 A: ");
  EXPECT_CONTAINS(ClippingMessage("current", "A", top, flat_top.size()),
                  "repeat the channel's maximum");
}

}  // namespace
}  // namespace eol::analysis
