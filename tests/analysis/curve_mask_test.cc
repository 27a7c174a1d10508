#include "analysis/qc/curve_mask.h"

#include <gtest/gtest.h>

namespace eol::analysis {
namespace {

Frf Flat(double re, double sigma) {
  Frf z;
  for (int f = 200; f <= 400; ++f) {
    z.freq_hz.push_back(f);
    z.value.emplace_back(re, 1.0);
    z.sigma.push_back(sigma);
  }
  return z;
}

CurveMask Band() {
  CurveMask m;
  m.name = "band";
  m.points = {{300.0, std::nullopt, 1.0}, {350.0, std::nullopt, 2.0}};
  return m;
}

TEST(CurveMask, CountsLinesAboveAnInterpolatedUpperBound) {
  Frf z = Flat(0.5, 0.01);
  z.value[130] = {1.8, 1.0};  // 330 Hz: bound there is 1.6
  const MaskCheck c = CheckMask(z, Band());
  EXPECT_EQ(c.lines_checked, 51);
  EXPECT_EQ(c.lines_outside, 1);
  EXPECT_DOUBLE_EQ(c.worst_f_hz, 330.0);
  EXPECT_NEAR(c.worst_excess, 0.2, 1e-12);
}

TEST(CurveMask, GuardSigmaKeepsNoiseOnTheEdgeFromFailing) {
  Frf z = Flat(0.5, 0.1);
  z.value[130] = {1.65, 1.0};  // 0.05 above the bound, half a sigma
  CurveMask m = Band();
  EXPECT_EQ(CheckMask(z, m).lines_outside, 1);
  m.guard_sigma = 3.0;
  EXPECT_EQ(CheckMask(z, m).lines_outside, 0);
}

TEST(CurveMask, LowerBoundOnMagnitude) {
  CurveMask m;
  m.name = "floor";
  m.quantity = MaskQuantity::kAbsOhm;
  m.points = {{200.0, 2.0, std::nullopt}, {400.0, 2.0, std::nullopt}};
  const MaskCheck c = CheckMask(Flat(0.5, 0.01), m);  // |Z| = 1.118 everywhere
  EXPECT_EQ(c.lines_outside, 201);
  EXPECT_EQ(m.Spec().limit.hi, 0.0);
}

TEST(CurveMask, InvalidMasksExplainWhy) {
  std::string why;
  CurveMask m = Band();
  m.points.pop_back();
  EXPECT_FALSE(m.IsValid(&why));
  EXPECT_EQ(why, "a mask needs at least two points");
}

}  // namespace
}  // namespace eol::analysis
