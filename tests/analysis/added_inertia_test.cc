// The added-inertia method (analysis/fit/added_inertia.h) on simulated data: two noisy
// measurements of one motor, without and with a known added inertia, give J_r, T, C_m and
// R_m in absolute units, with sigmas that match the Monte Carlo spread.
#include "analysis/fit/added_inertia.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

namespace eol::analysis {
namespace {

using Cplx = std::complex<double>;

PmsmParams Motor(double inertia) {
  PmsmParams p;
  p.r_ohm = 0.5;
  p.l_h = 2e-3;
  p.transmission_nm_per_a = 0.05;
  p.inertia_kg_m2 = inertia;
  const double w0 = 2 * std::numbers::pi * 390.0;
  p.compliance_rad_per_nm = 1.0 / (1e-4 * w0 * w0);  // the spring of the 1e-4 rotor at 390 Hz
  p.damping_nms_per_rad = 1e-4 * w0 / 50.0;
  return p;
}

FitSummary Measure(const PmsmParams& p, double sigma, std::mt19937_64* rng) {
  Frf z;
  std::normal_distribution<double> n(0.0, sigma / std::sqrt(2.0));
  for (int k = 200; k <= 800; ++k) {
    z.freq_hz.push_back(k);
    z.value.push_back(ElectricalImpedance(p, k) + Cplx(n(*rng), n(*rng)));
  }
  z.sigma.assign(z.size(), sigma);
  ResonanceFitOptions o;
  o.f0_min_hz = 250;
  o.f0_max_hz = 700;
  return FitMotionalResonance(z, o);
}

constexpr double kJ = 1e-4, kDj = 2e-5;  // +20 %: f0 390 -> 356 Hz

TEST(AddedInertia, RecoversThePhysicalParametersInAbsoluteUnits) {
  std::mt19937_64 rng(42);
  const FitSummary a = Measure(Motor(kJ), 0.02, &rng);
  const FitSummary b = Measure(Motor(kJ + kDj), 0.02, &rng);
  ASSERT_TRUE(a.usable && b.usable);
  const AddedInertiaSummary s = EstimateFromAddedInertia(a, b, kDj);
  ASSERT_TRUE(s.usable) << s.message;
  const PmsmParams truth = Motor(kJ);
  auto check = [&](const char* name, double expected, double max_rel_sigma) {
    const FittedParameter* p = s.Find(name);
    ASSERT_NE(p, nullptr) << name;
    EXPECT_NEAR(p->value, expected, 4 * p->sigma) << name << ": " << s.message;
    EXPECT_LT(p->sigma, max_rel_sigma * expected) << name;
    RecordProperty(name, std::to_string(p->value) + " +- " + std::to_string(p->sigma));
  };
  check("J_r_kg_m2", kJ, 0.01);
  check("T_nm_per_a", truth.transmission_nm_per_a, 0.01);
  check("Cm_rad_per_nm", truth.compliance_rad_per_nm, 0.01);
  check("Rm_nms_per_rad", truth.damping_nms_per_rad, 0.03);  // Q is known to ~1.5 %
  EXPECT_LT(std::abs(s.rp_consistency_z), 4.0);
  EXPECT_LT(std::abs(s.q_consistency_z), 4.0);
}

TEST(AddedInertia, SigmasMatchTheMonteCarloSpread) {
  std::mt19937_64 rng(7);
  const int runs = 100;
  double sum = 0.0, sum2 = 0.0, sigma_sum = 0.0;
  int covered = 0;
  for (int i = 0; i < runs; ++i) {
    const AddedInertiaSummary s = EstimateFromAddedInertia(
        Measure(Motor(kJ), 0.02, &rng), Measure(Motor(kJ + kDj), 0.02, &rng), kDj);
    ASSERT_TRUE(s.usable) << s.message;
    const FittedParameter* j = s.Find("J_r_kg_m2");
    sum += j->value;
    sum2 += j->value * j->value;
    sigma_sum += j->sigma;
    if (std::abs(j->value - kJ) < 2 * j->sigma) ++covered;
  }
  const double mean = sum / runs;
  const double sd = std::sqrt(sum2 / runs - mean * mean);
  const double sigma_mean = sigma_sum / runs;
  RecordProperty("j_sd_over_sigma", std::to_string(sd / sigma_mean));
  EXPECT_NEAR(sd / sigma_mean, 1.0, 0.2);
  EXPECT_NEAR(mean, kJ, 3 * sd / std::sqrt(runs));
  EXPECT_GE(covered, 88);  // ~95 % expected
}

TEST(AddedInertia, RefusesWhenF0DidNotDrop) {
  std::mt19937_64 rng(1);
  const FitSummary a = Measure(Motor(kJ), 0.02, &rng);
  const AddedInertiaSummary s = EstimateFromAddedInertia(a, a, kDj);
  EXPECT_FALSE(s.usable);
  EXPECT_NE(s.message.find("did not lower f0"), std::string::npos) << s.message;
  EXPECT_FALSE(EstimateFromAddedInertia(a, a, -1.0).usable);
}

}  // namespace
}  // namespace eol::analysis
