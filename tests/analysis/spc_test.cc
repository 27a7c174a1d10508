// Known answers for the control charts, run rules and capability indices (analysis/qc/spc.h)
// on data small enough to compute by hand; each expected value is worked out in a comment.
#include "analysis/qc/spc.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <random>

namespace eol::analysis {
namespace {

Limit Both(double lo, double hi) {
  Limit l;
  l.lo = lo;
  l.hi = hi;
  return l;
}

TEST(SpcConstants, TableEndsAndOutside) {
  EXPECT_DOUBLE_EQ(SpcConstantsFor(2)->d2, 1.128);
  EXPECT_DOUBLE_EQ(SpcConstantsFor(2)->d4, 3.267);
  EXPECT_DOUBLE_EQ(SpcConstantsFor(5)->a2, 0.577);
  EXPECT_DOUBLE_EQ(SpcConstantsFor(5)->d2, 2.326);
  EXPECT_DOUBLE_EQ(SpcConstantsFor(10)->d3, 0.223);
  EXPECT_FALSE(SpcConstantsFor(1).has_value());
  EXPECT_FALSE(SpcConstantsFor(11).has_value());
  // A2 = 3 / (d2 sqrt(n)) holds for every row to the table's rounding.
  for (std::size_t n = 2; n <= 10; ++n) {
    const SpcConstants k = *SpcConstantsFor(n);
    EXPECT_NEAR(k.a2, 3.0 / (k.d2 * std::sqrt(static_cast<double>(n))), 1.5e-3) << n;
  }
}

TEST(IMr, KnownAnswer) {
  // x = 10 12 11 13 12 14 13 15: mean 100 / 8 = 12.5; MR = 2 1 2 1 2 1 2, MRbar = 11 / 7
  // = 1.57142857; UCL = 12.5 + 2.66 MRbar = 16.68; LCL = 8.32; MR UCL = 3.267 MRbar =
  // 5.13385714; sigma_within = MRbar / 1.128 = 1.39311044.
  const IMrChart c = ComputeIMr({10, 12, 11, 13, 12, 14, 13, 15});
  ASSERT_TRUE(c.usable) << c.message;
  ASSERT_EQ(c.moving_ranges.size(), 7u);
  EXPECT_DOUBLE_EQ(c.moving_ranges[0], 2.0);
  EXPECT_NEAR(c.mr_bar, 1.57142857, 1e-8);
  EXPECT_NEAR(c.individuals.centre, 12.5, 1e-12);
  EXPECT_NEAR(c.individuals.ucl, 16.68, 1e-8);
  EXPECT_NEAR(c.individuals.lcl, 8.32, 1e-8);
  EXPECT_NEAR(c.moving_range.ucl, 5.13385714, 1e-8);
  EXPECT_DOUBLE_EQ(c.moving_range.lcl, 0.0);
  EXPECT_NEAR(c.sigma_within, 1.39311044, 1e-8);
  EXPECT_FALSE(ComputeIMr({1.0}).usable);
}

TEST(XbarR, KnownAnswerSubgroupsOfFive) {
  // {1 2 3 4 5}: mean 3, R 4; {2 3 4 5 6}: mean 4, R 4; {3 4 5 6 10}: mean 5.6, R 7; the 16th
  // value (99) is an incomplete subgroup and left out. xbarbar = 12.6 / 3 = 4.2, Rbar = 5;
  // UCL = 4.2 + 0.577 * 5 = 7.085, LCL = 1.315; R UCL = 2.114 * 5 = 10.57, R LCL = 0;
  // sigma_within = 5 / 2.326 = 2.14961307.
  const XbarRChart c = ComputeXbarR({1, 2, 3, 4, 5, 2, 3, 4, 5, 6, 3, 4, 5, 6, 10, 99}, 5);
  ASSERT_TRUE(c.usable) << c.message;
  ASSERT_EQ(c.means.size(), 3u);
  EXPECT_EQ(c.left_out, 1u);
  EXPECT_NEAR(c.means[2], 5.6, 1e-12);
  EXPECT_DOUBLE_EQ(c.ranges[2], 7.0);
  EXPECT_NEAR(c.xbar.centre, 4.2, 1e-12);
  EXPECT_NEAR(c.r_bar, 5.0, 1e-12);
  EXPECT_NEAR(c.xbar.ucl, 7.085, 1e-9);
  EXPECT_NEAR(c.xbar.lcl, 1.315, 1e-9);
  EXPECT_NEAR(c.range.ucl, 10.57, 1e-9);
  EXPECT_DOUBLE_EQ(c.range.lcl, 0.0);
  EXPECT_NEAR(c.sigma_within, 2.14961307, 1e-8);
  // n = 7 has D3 > 0: R LCL = 0.076 Rbar.
  const XbarRChart seven = ComputeXbarR({1, 2, 3, 4, 5, 6, 7, 1, 2, 3, 4, 5, 6, 9}, 7);
  ASSERT_TRUE(seven.usable) << seven.message;
  EXPECT_NEAR(seven.range.lcl, 0.076 * 7.0, 1e-12);          // Rbar = (6 + 8) / 2 = 7
  EXPECT_FALSE(ComputeXbarR({1, 2, 3, 4, 5, 6}, 5).usable);  // one subgroup
  EXPECT_FALSE(ComputeXbarR({1, 2, 3, 4, 5, 6}, 11).usable);
}

TEST(RunRules, ShiftFiresRule2AtTheNinthShiftedPoint) {
  // 30 points alternating +1, -1 (stationary: no run, no trend), then 12 points alternating
  // 3.5, 2.5 (a shift). Centre = (0 * 30 + 3 * 12) / 42 = 0.857; MRbar = (29 * 2 + 4.5 +
  // 11 * 1) / 41 = 1.79268; UCL = 0.857 + 2.66 * 1.79268 = 5.63, so no point is beyond it.
  // The shifted points are all above the centre: rule 2 completes at index 30 + 8 = 38.
  std::vector<double> x;
  for (int i = 0; i < 30; ++i) x.push_back(i % 2 == 0 ? 1.0 : -1.0);
  for (int i = 0; i < 12; ++i) x.push_back(i % 2 == 0 ? 3.5 : 2.5);
  const IMrChart c = ComputeIMr(x);
  ASSERT_TRUE(c.usable);
  EXPECT_NEAR(c.individuals.centre, 36.0 / 42.0, 1e-12);
  EXPECT_NEAR(c.mr_bar, 73.5 / 41.0, 1e-12);
  const std::vector<SpcAlarm> alarms = ApplyRunRules(x, c.individuals);
  ASSERT_EQ(alarms.size(), 1u);
  EXPECT_EQ(alarms[0].rule, 2);
  EXPECT_EQ(alarms[0].index, 38u);
  EXPECT_EQ(alarms[0].first, 30u);
  EXPECT_NE(alarms[0].message.find("9 points in a row above"), std::string::npos)
      << alarms[0].message;
  // The stationary part alone raises nothing.
  const std::vector<double> head(x.begin(), x.begin() + 30);
  EXPECT_TRUE(ApplyRunRules(head, ComputeIMr(head).individuals).empty());
}

TEST(RunRules, SpikeFiresRule1AndRampFiresRule3) {
  // Limits given: centre 0, +-3. Index 4 at 3.5 is beyond the UCL (rule 1); indices 6..11
  // rise 0.1 .. 0.6 (6 points, 5 steps up: rule 3 at 11, first 6; index 5 at 0.5 is above
  // index 6, so the rise starts at 6). Indices 5..11 are 7 above the centre: no rule 2.
  const ControlLimits l{0.0, -3.0, 3.0};
  const std::vector<double> x = {0.5, -0.5, 0.5, -0.5, 3.5, 0.5, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6};
  const std::vector<SpcAlarm> a = ApplyRunRules(x, l);
  ASSERT_EQ(a.size(), 2u);
  EXPECT_EQ(a[0].rule, 1);
  EXPECT_EQ(a[0].index, 4u);
  EXPECT_NE(a[0].message.find("beyond the UCL 3"), std::string::npos) << a[0].message;
  EXPECT_EQ(a[1].rule, 3);
  EXPECT_EQ(a[1].index, 11u);
  EXPECT_EQ(a[1].first, 6u);
  // Rules switched off stay silent.
  SpcRuleOptions off;
  off.beyond_limits = false;
  off.trend_length = 0;
  EXPECT_TRUE(ApplyRunRules(x, l, off).empty());
  std::string why;
  off.trend_length = 2;
  EXPECT_FALSE(off.IsValid(&why));
}

// Normal noise from mt19937 (its sequence is fixed by the standard) through Box-Muller, so
// the samples do not depend on the library's normal_distribution.
std::vector<double> Noise(unsigned seed, int n, double shift_from = -1, double shift = 0.0) {
  std::mt19937 g(seed);
  std::vector<double> x;
  for (int i = 0; i < n; ++i) {
    const double u1 = (g() + 1.0) / 4294967297.0, u2 = g() / 4294967296.0;
    const double z = std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
    x.push_back(z + (shift_from >= 0 && i >= shift_from ? shift : 0.0));
  }
  return x;
}

TEST(RunRules, ShiftOfTwoSigmaIsCaughtAndStationaryNoiseRarelyAlarms) {
  // 200 series each: 60 values N(0, 1), or the same with +2 sigma from value 40 on. The
  // shifted third sits ~1.3 sigma above the centre (the limits are computed from the whole
  // series, shift included): 9 in a row above comes in about 95 % of the series (191 of
  // these 200); the contract asked is at least 90 %, most of them by rule 2 in the shift. For
  // stationary noise the three rules together fire in roughly 1 - 0.9973^60 (rule 1, 15 %) plus ~
  // 52 * 2 / 2^9 (rule 2, ~20 %) plus ~ 55 * 2 / 6! (rule 3, ~15 %) of the series: well under 60 %.
  int shifted_caught = 0, shift_rule2 = 0, stationary_alarmed = 0;
  for (unsigned seed = 1; seed <= 200; ++seed) {
    const std::vector<double> s = Noise(seed, 60, 40, 2.0);
    const auto a = ApplyRunRules(s, ComputeIMr(s).individuals);
    shifted_caught += !a.empty();
    for (const SpcAlarm& e : a) shift_rule2 += e.rule == 2 && e.first >= 35;
    const std::vector<double> q = Noise(seed + 1000, 60);
    stationary_alarmed += !ApplyRunRules(q, ComputeIMr(q).individuals).empty();
  }
  std::cout << "shifted series alarmed " << shifted_caught << "/200 (rule 2 in the shift "
            << shift_rule2 << "), stationary series alarmed " << stationary_alarmed << "/200\n";
  EXPECT_GE(shifted_caught, 180);
  EXPECT_GE(shift_rule2, 150);  // and by the rule for a shift, in the shifted part
  EXPECT_LE(stationary_alarmed, 120);
  EXPECT_LT(stationary_alarmed, shifted_caught / 2);
}

TEST(Capability, CpFromMovingRangesPpFromOverallSd) {
  // {1..5}: mean 3, s = sqrt(10 / 4) = 1.58113883: Pp = 10 / (6 s) = 1.05409255;
  // Ppk = min(10 - 3, 3 - 0) / (3 s) = 0.63245553. MR = 1 1 1 1: sigma_within = 1 / 1.128
  // = 0.88652482; Cp = 10 / (6 * 0.88652482) = 1.88; Cpk = 3 / (3 * 0.88652482) = 1.128.
  const CapabilityIndices c = ComputeCapabilityIndices({1, 2, 3, 4, 5}, Both(0, 10));
  ASSERT_TRUE(c.usable) << c.message;
  EXPECT_EQ(c.sample.n, 5u);
  EXPECT_NEAR(c.sample.sd, 1.58113883, 1e-8);
  EXPECT_NEAR(*c.pp, 1.05409255, 1e-8);
  EXPECT_NEAR(*c.ppk, 0.63245553, 1e-8);
  EXPECT_NEAR(c.sigma_within, 0.88652482, 1e-8);
  EXPECT_NEAR(*c.cp, 1.88, 1e-9);
  EXPECT_NEAR(*c.cpk, 1.128, 1e-9);
  EXPECT_EQ(c.within_method, "MRbar/d2 (d2 = 1.128)");
}

TEST(Capability, SubgroupRangesAndOneSidedLimit) {
  // The X-bar/R data above (15 values in 3 subgroups of 5; sigma_within = 5 / 2.326), hi = 10
  // only: no Cp, no Pp; mean = 63 / 15 = 4.2; Cpk = (10 - 4.2) / (3 * 2.14961307) = 0.89938.
  Limit hi_only;
  hi_only.hi = 10;
  const CapabilityIndices c =
      ComputeCapabilityIndices({1, 2, 3, 4, 5, 2, 3, 4, 5, 6, 3, 4, 5, 6, 10}, hi_only, 5);
  ASSERT_TRUE(c.usable) << c.message;
  EXPECT_FALSE(c.cp.has_value());
  EXPECT_FALSE(c.pp.has_value());
  EXPECT_NEAR(*c.cpk, 5.8 / (3.0 * 5.0 / 2.326), 1e-9);
  EXPECT_NEAR(*c.cpk, 0.89938, 1e-5);
  EXPECT_EQ(c.within_method, "Rbar/d2 (n = 5, d2 = 2.326)");
}

TEST(Capability, NoSpreadOrTooFewValuesIsNotUsable) {
  EXPECT_FALSE(ComputeCapabilityIndices({2.0}, Both(0, 10)).usable);
  const CapabilityIndices flat = ComputeCapabilityIndices({2, 2, 2}, Both(0, 10));
  EXPECT_FALSE(flat.usable);
  EXPECT_FALSE(flat.cpk.has_value());
  EXPECT_FALSE(flat.ppk.has_value());
  EXPECT_NE(flat.message.find("no spread"), std::string::npos);
}

}  // namespace
}  // namespace eol::analysis
