// Two close modes (analysis/fit/modes_fit.h): one soft magnet is found as two modes, not
// averaged into one; a good rotor stays one mode.
#include "analysis/fit/modes_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "analysis/model/rotor_chain.h"

namespace eol::analysis {
namespace {

using Cplx = std::complex<double>;

std::vector<double> Lines(double lo, double hi) {
  std::vector<double> f;
  for (double x = lo; x <= hi + 1e-9; x += 1.0) f.push_back(x);
  return f;
}

void AddNoise(double sigma, std::uint64_t seed, Frf* z) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, sigma / std::sqrt(2.0));
  for (auto& v : z->value) v += Cplx(n(rng), n(rng));
  z->sigma.assign(z->size(), sigma);
}

double Value(const FitSummary& s, const std::string& name) {
  const FittedParameter* p = s.Find(name);
  return p ? p->value : std::nan("");
}
double Sigma(const FitSummary& s, const std::string& name) {
  const FittedParameter* p = s.Find(name);
  return p ? p->sigma : std::nan("");
}

ModesFitOptions Options(double lo, double hi) {
  ModesFitOptions o;
  o.single.f0_min_hz = lo;
  o.single.f0_max_hz = hi;
  o.single.q_min = 5;
  o.single.q_max = 500;
  return o;
}

TEST(ModesFit, CloseModesAreResolvedNotAveraged) {
  // 390 Hz and 402 Hz, Q 50 each: 1.5 half-power bandwidths apart, a single merged peak.
  const MultiModeImpedance truth{0.5, 2e-3, {{0.5, 390.0, 50.0}, {0.3, 402.0, 50.0}}};
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    Frf z;
    z.freq_hz = Lines(200, 800);
    for (double f : z.freq_hz) z.value.push_back(truth.At(f));
    AddNoise(0.02, seed, &z);
    const ModesFitSummary s = FitMotionalModes(z, Options(250, 700));
    ASSERT_TRUE(s.usable) << s.message;
    ASSERT_EQ(s.mode_count, 2) << s.message;
    EXPECT_NEAR(Value(s.fit, "f1_hz"), 390.0, 4 * Sigma(s.fit, "f1_hz")) << s.message;
    EXPECT_NEAR(Value(s.fit, "f2_hz"), 402.0, 4 * Sigma(s.fit, "f2_hz")) << s.message;
    EXPECT_NEAR(Value(s.fit, "Rp1_ohm"), 0.5, 4 * Sigma(s.fit, "Rp1_ohm"));
    EXPECT_NEAR(s.fit.chi2_per_dof, 1.0, 0.15);
    // The one-mode fit lands in between and does not explain the data.
    ASSERT_EQ(s.candidates.size(), 2u);
    EXPECT_GT(s.candidates[0].chi2, s.candidates[1].chi2 + 100.0);
  }
}

TEST(ModesFit, OneSoftMagnetOnARigidFixtureIsTwoModes) {
  RotorChainParams rotor;
  rotor.fixture.reset();
  rotor.soft_magnets = {0};
  const ClampedMotor motor{0.5, 2e-3, 0.05, BuildRotorChain(rotor)};
  const auto terms = motor.ModalTerms();  // 567.3 Hz (Rp 0.12) and 723.7 Hz (Rp 0.22)
  Frf z = motor.Evaluate(Lines(200, 900));
  AddNoise(0.02, 7, &z);
  const ModesFitSummary s = FitMotionalModes(z, Options(250, 850));
  ASSERT_TRUE(s.usable) << s.message;
  ASSERT_EQ(s.mode_count, 2) << s.message;
  // The modal terms are the proportional-damping approximation: compare within 4 sigma plus
  // 0.05 % of f.
  EXPECT_NEAR(Value(s.fit, "f1_hz"), terms[0].f0_hz, 4 * Sigma(s.fit, "f1_hz") + 0.3);
  EXPECT_NEAR(Value(s.fit, "f2_hz"), terms[1].f0_hz, 4 * Sigma(s.fit, "f2_hz") + 0.4);
  EXPECT_NEAR(Value(s.fit, "Rp1_ohm"), terms[0].rp_ohm, 0.1 * terms[0].rp_ohm);
  EXPECT_NEAR(Value(s.fit, "Rp2_ohm"), terms[1].rp_ohm, 0.1 * terms[1].rp_ohm);
  EXPECT_LT(s.fit.chi2_per_dof, 1.2);
  RecordProperty("message", s.message);
}

TEST(ModesFit, GoodRotorStaysOneMode) {
  const ClampedMotor motor{0.5, 2e-3, 0.05, BuildRotorChain(RotorChainParams{})};
  for (std::uint64_t seed : {11u, 12u, 13u}) {
    Frf z = motor.Evaluate(Lines(200, 800));
    AddNoise(0.02, seed, &z);
    const ModesFitSummary s = FitMotionalModes(z, Options(250, 700));
    ASSERT_TRUE(s.usable) << s.message;
    EXPECT_EQ(s.mode_count, 1) << s.message;
    EXPECT_NEAR(Value(s.fit, "f0_hz"), 390.0, 0.5);
    EXPECT_EQ(s.fit.model, "R+sL+parallel-RLC");
  }
}

TEST(ModesFit, WithoutSigmaTheInformationCriterionStillDecides) {
  const MultiModeImpedance truth{0.5, 2e-3, {{0.5, 390.0, 50.0}, {0.3, 402.0, 50.0}}};
  Frf z;
  z.freq_hz = Lines(200, 800);
  for (double f : z.freq_hz) z.value.push_back(truth.At(f));
  AddNoise(0.02, 21, &z);
  z.sigma.clear();
  const ModesFitSummary s = FitMotionalModes(z, Options(250, 700));
  ASSERT_TRUE(s.usable) << s.message;
  EXPECT_EQ(s.mode_count, 2) << s.message;
  EXPECT_TRUE(s.fit.sigma_estimated);
  EXPECT_NEAR(s.fit.estimated_sigma, 0.02, 0.002);  // complex std per line
}

TEST(ModesFit, ModelReproducesTheFit) {
  const MultiModeImpedance truth{0.5, 2e-3, {{0.5, 390.0, 50.0}, {0.3, 430.0, 40.0}}};
  Frf z;
  z.freq_hz = Lines(200, 800);
  for (double f : z.freq_hz) z.value.push_back(truth.At(f));
  z.sigma.assign(z.size(), 1e-4);
  const ModesFitSummary s = FitMotionalModes(z, Options(250, 700));
  ASSERT_EQ(s.mode_count, 2) << s.message;
  const MultiModeImpedance m = s.Model();
  ASSERT_EQ(m.modes.size(), 2u);
  EXPECT_NEAR(m.modes[1].f0_hz, 430.0, 1e-6);
  EXPECT_NEAR(m.modes[1].q, 40.0, 1e-5);
  EXPECT_LT(std::abs(m.At(415.0) - truth.At(415.0)), 1e-9);
}

}  // namespace
}  // namespace eol::analysis
