// The two-mass torsional model (analysis/model/two_mass.h): identifiable form against the
// physical equation, the mapping back with Kt given, and the weighted fit on synthetic data.
#include "analysis/model/two_mass.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

namespace eol::analysis {
namespace {

#define EXPECT_CONTAINS(haystack, needle) \
  EXPECT_PRED_FORMAT2(::testing::IsSubstring, needle, haystack)

// About the bench: anti-resonance 53 Hz, resonance 77 Hz.
TwoMassSystem Bench() {
  TwoMassSystem m;
  m.kt_nm_per_a = 0.5;
  m.j2_kg_m2 = 1.2e-3;
  m.k_nm_per_rad = m.j2_kg_m2 * std::pow(2.0 * std::numbers::pi * 53.0, 2.0);
  m.j1_kg_m2 = m.j2_kg_m2 / ((77.0 / 53.0) * (77.0 / 53.0) - 1.0);
  m.c_nms_per_rad = 2.0 * 0.015 * std::sqrt(m.k_nm_per_rad * m.j2_kg_m2);
  return m;
}

TEST(TwoMassTest, TextbookFormAndFrequencies) {
  const TwoMassSystem m = Bench();
  const TwoMassResponse r = m.Response();
  EXPECT_NEAR(r.f_ar_hz, 53.0, 1e-9);
  EXPECT_NEAR(r.f_r_hz, 77.0, 1e-9);
  EXPECT_NEAR(r.zeta_ar, 0.015, 1e-12);
  EXPECT_NEAR(r.ZetaR(), 0.015 * 77.0 / 53.0, 1e-12);
  for (double f : {5.0, 40.0, 53.0, 77.0, 200.0}) {
    const std::complex<double> s(0.0, 2.0 * std::numbers::pi * f);
    const double j1 = m.j1_kg_m2, j2 = m.j2_kg_m2, k = m.k_nm_per_rad, c = m.c_nms_per_rad;
    const std::complex<double> textbook = m.kt_nm_per_a * (j2 * s * s + c * s + k) /
                                          (s * (j1 * j2 * s * s + (j1 + j2) * (c * s + k)));
    EXPECT_NEAR(std::abs(m.Mobility(f) - textbook), 0.0, 1e-12 * std::abs(textbook)) << f;
    EXPECT_NEAR(std::abs(r.At(f) - textbook), 0.0, 1e-9 * std::abs(textbook)) << f;
  }
}

TEST(TwoMassTest, FrictionAndRoundTrip) {
  TwoMassSystem m = Bench();
  m.b1_nms_per_rad = 0.02;
  const TwoMassResponse r = m.Response();
  for (double f : {1.0, 20.0, 60.0, 150.0})
    EXPECT_NEAR(std::abs(r.At(f) - m.Mobility(f)), 0.0, 1e-9 * std::abs(m.Mobility(f))) << f;
  const TwoMassSystem back = TwoMassSystem::FromResponse(r, m.kt_nm_per_a);
  EXPECT_NEAR(back.j1_kg_m2 / m.j1_kg_m2, 1.0, 1e-12);
  EXPECT_NEAR(back.j2_kg_m2 / m.j2_kg_m2, 1.0, 1e-12);
  EXPECT_NEAR(back.k_nm_per_rad / m.k_nm_per_rad, 1.0, 1e-12);
  EXPECT_NEAR(back.c_nms_per_rad / m.c_nms_per_rad, 1.0, 1e-12);
  EXPECT_NEAR(back.b1_nms_per_rad / m.b1_nms_per_rad, 1.0, 1e-12);
}

Frf Noisy(const TwoMassResponse& r, double rel_sigma, std::uint64_t seed) {
  std::vector<double> f;
  for (int k = 11; k <= 250; ++k) f.push_back(k);
  Frf h = r.Evaluate(f);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  for (std::size_t k = 0; k < h.size(); ++k) {
    const double s = rel_sigma * std::abs(h.value[k]);
    h.sigma.push_back(s);
    h.value[k] += std::complex<double>(n(rng), n(rng)) * (s / std::sqrt(2.0));
  }
  return h;
}

TEST(TwoMassTest, FitRecoversSyntheticTruth) {
  TwoMassResponse truth = Bench().Response();
  truth.delay_s = 2e-4;
  const Frf h = Noisy(truth, 0.01, 3);
  TwoMassFitOptions o;
  o.fit_delay = true;
  const TwoMassFit fit = FitTwoMass(h, o);
  ASSERT_TRUE(fit.usable) << fit.message;
  EXPECT_NEAR(fit.chi2_per_dof, 1.0, 0.2);
  const auto near = [&](const char* name, double want) {
    const FittedParameter* p = fit.Find(name);
    ASSERT_NE(p, nullptr) << name;
    EXPECT_NEAR(p->value, want, 4.0 * p->sigma) << name;
  };
  near("g_rad_per_s2_per_a", truth.gain_rad_per_s2_per_a);
  near("f_ar_hz", 53.0);
  near("f_r_hz", 77.0);
  near("zeta_ar", truth.zeta_ar);
  near("delay_s", truth.delay_s);
}

TEST(TwoMassTest, RejectsImpedanceAndMissingAntiResonance) {
  Frf z = Noisy(Bench().Response(), 0.01, 4);
  z.quantity = Quantity::kImpedanceOhm;
  EXPECT_CONTAINS(FitTwoMass(z, {}).message, "the two-mass fit needs mobility");
  TwoMassFitOptions above;
  above.f_lo_hz = 60.0;  // the anti-resonance is below the band
  above.f_hi_hz = 250.0;
  const TwoMassFit f = FitTwoMass(Noisy(Bench().Response(), 0.01, 5), above);
  EXPECT_FALSE(f.usable);
  EXPECT_CONTAINS(f.message, "no anti-resonance");
}

}  // namespace
}  // namespace eol::analysis
