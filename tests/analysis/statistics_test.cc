// Known answers for drift and the type-1 gauge study (analysis/qc/statistics.h),
// on data small enough to compute by hand; each expected value is worked out in a comment.
#include "analysis/qc/statistics.h"

#include <gtest/gtest.h>

#include <cmath>

namespace eol::analysis {
namespace {

Limit Both(double lo, double hi) {
  Limit l;
  l.lo = lo;
  l.hi = hi;
  return l;
}

TEST(Drift, KnownAnswerNoisyLine) {
  // y_i = i + 0.5 (-1)^i, i = 0..9. Sxx = 82.5, sum (x - xbar) e = -2.5, so
  // b = 1 - 2.5 / 82.5 = 0.96969697; SSE = 2.5 - 2.5^2 / 82.5 = 2.42424242;
  // sigma_b = sqrt(SSE / 8 / 82.5) = 0.06060606; t = 16.0; change = 9 b = 8.72727273.
  std::vector<double> y;
  for (int i = 0; i < 10; ++i) y.push_back(i + 0.5 * (i % 2 == 0 ? 1 : -1));
  const DriftSummary d = DetectDrift(y, Both(0, 50), "x", "u");
  ASSERT_TRUE(d.usable) << d.message;
  EXPECT_NEAR(d.slope_per_test, 0.96969697, 1e-8);
  EXPECT_NEAR(d.slope_sigma, 0.06060606, 1e-8);
  EXPECT_NEAR(d.t, 16.0, 1e-6);
  EXPECT_NEAR(d.change, 8.72727273, 1e-7);
  EXPECT_NEAR(*d.change_of_tolerance, 8.72727273 / 50, 1e-8);
  EXPECT_TRUE(d.alarm);
  EXPECT_NE(d.message.find("drift alarm: x rises"), std::string::npos) << d.message;
}

TEST(Drift, NoTrendNoAlarm) {
  // Alternating values around 5 with no trend: |t| is small.
  std::vector<double> y;
  for (int i = 0; i < 20; ++i) y.push_back(5.0 + (i % 2 == 0 ? 1.0 : -1.0) * (1 + i % 3));
  const DriftSummary d = DetectDrift(y, Both(0, 10), "x", "u");
  ASSERT_TRUE(d.usable);
  EXPECT_LT(std::abs(d.t), 4.0);
  EXPECT_FALSE(d.alarm);
  EXPECT_NE(d.message.find("no alarm"), std::string::npos);
}

TEST(Drift, SignificantButSmallAgainstTheToleranceDoesNotAlarm) {
  // The same line as above (t = 16, change 8.7) against a tolerance of 1000: 0.9 % < 10 %.
  std::vector<double> y;
  for (int i = 0; i < 10; ++i) y.push_back(i + 0.5 * (i % 2 == 0 ? 1 : -1));
  const DriftSummary d = DetectDrift(y, Both(0, 1000), "x", "u");
  EXPECT_FALSE(d.alarm);
  EXPECT_NE(d.message.find("significant, but below 10 % of the tolerance"), std::string::npos)
      << d.message;
}

TEST(Drift, TooFewTestsIsNotUsable) {
  const DriftSummary d = DetectDrift({1, 2, 3}, Both(0, 10), "x", "u");
  EXPECT_FALSE(d.usable);
  EXPECT_FALSE(d.alarm);
  EXPECT_NE(d.message.find("too few tests"), std::string::npos);
}

// Ten repeats: mean 10.0, deviations six of +-0.1 and four of 0, s = sqrt(0.06 / 9) = 0.08164966.
const std::vector<double> kRepeats = {9.9, 10.0, 10.1, 10.0, 9.9, 10.1, 10.0, 10.0, 9.9, 10.1};

TEST(Gauge, KnownAnswerSixSigma) {
  // T = 2: Cg = 0.2 * 2 / (6 s) = 0.81649658; reference 9.95, bias 0.05:
  // Cgk = (0.2 - 0.05) / (3 s) = 0.61237244.
  const GaugeStudy g = GaugeType1(kRepeats, Both(9, 11), 9.95);
  ASSERT_TRUE(g.usable) << g.message;
  EXPECT_NEAR(g.sample.sd, 0.08164966, 1e-8);
  EXPECT_DOUBLE_EQ(g.tolerance, 2.0);
  EXPECT_NEAR(g.cg, 0.81649658, 1e-8);
  EXPECT_NEAR(*g.bias, 0.05, 1e-12);
  EXPECT_NEAR(*g.cgk, 0.61237244, 1e-8);
  EXPECT_FALSE(g.repeatable);
  EXPECT_FALSE(*g.capable);
}

TEST(Gauge, KnownAnswerFourSigma) {
  // L = 4: Cg = 0.4 / (4 s) = 1.22474487; Cgk = 0.15 / (2 s) = 0.91855865.
  GaugeOptions o;
  o.sigma_span = 4;
  const GaugeStudy g = GaugeType1(kRepeats, Both(9, 11), 9.95, o);
  EXPECT_NEAR(g.cg, 1.22474487, 1e-8);
  EXPECT_NEAR(*g.cgk, 0.91855865, 1e-8);
}

TEST(Gauge, CapableWithAWiderTolerance) {
  // T = 4, reference = mean: Cg = Cgk = 0.8 / (6 s) = 1.63299316 >= 1.33.
  const GaugeStudy g = GaugeType1(kRepeats, Both(8, 12), 10.0);
  EXPECT_NEAR(g.cg, 1.63299316, 1e-8);
  EXPECT_NEAR(*g.cgk, 1.63299316, 1e-8);
  EXPECT_TRUE(g.repeatable);
  EXPECT_TRUE(*g.capable);
  EXPECT_NE(g.message.find(": capable"), std::string::npos) << g.message;
}

TEST(Gauge, WithoutReferenceNoCgkAndSaysSo) {
  const GaugeStudy g = GaugeType1(kRepeats, Both(8, 12), std::nullopt);
  ASSERT_TRUE(g.usable);
  EXPECT_FALSE(g.cgk.has_value());
  EXPECT_FALSE(g.capable.has_value());
  EXPECT_NE(g.message.find("no reference value"), std::string::npos);
}

TEST(Gauge, RefusesOneSidedToleranceAndTooFewRepeats) {
  Limit hi_only;
  hi_only.hi = 11;
  const GaugeStudy one_sided = GaugeType1(kRepeats, hi_only, std::nullopt);
  EXPECT_FALSE(one_sided.usable);
  EXPECT_NE(one_sided.message.find("two-sided tolerance"), std::string::npos);
  const GaugeStudy few = GaugeType1({10.0, 10.1, 9.9}, Both(9, 11), std::nullopt);
  EXPECT_FALSE(few.usable);
  EXPECT_NE(few.message.find("too few repeats (3 < 10"), std::string::npos) << few.message;
  GaugeOptions bad;
  bad.sigma_span = 5;
  EXPECT_NE(GaugeType1(kRepeats, Both(9, 11), std::nullopt, bad).message.find("4 or 6"),
            std::string::npos);
}

}  // namespace
}  // namespace eol::analysis
