// The second-mode test of the impedance analysis (impedance_analysis.h,
// second_mode_chi2_drop): only when asked; on a one-mode motor with noise it scatters as a
// few-parameter chi2 drop; a weak local mode beside the rotor's (a soft magnet, 1/40 of the
// peak) drops chi2 by far more, while chi2/dof hardly moves.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "analysis/fit/modes_fit.h"
#include "analysis/impedance_analysis.h"
#include "analysis/qc/measurement_names.h"

namespace eol::analysis {
namespace {

// 601 lines 200-800 Hz of the motor (R 0.5 ohm, L 2 mH, rotor mode 390 Hz, Q 50, Rp 0.6 ohm)
// plus, when local_rp > 0, a local mode at 590 Hz (Q 30), with complex noise of sigma per line.
Frf Measure(double local_rp, double sigma, unsigned seed) {
  MultiModeImpedance m;
  m.r_ohm = 0.5;
  m.l_h = 2e-3;
  m.modes.push_back({0.6, 390.0, 50.0});
  if (local_rp > 0.0) m.modes.push_back({local_rp, 590.0, 30.0});
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, sigma / std::sqrt(2.0));
  Frf z;
  for (int k = 0; k <= 600; ++k) {
    const double f = 200.0 + k;
    z.freq_hz.push_back(f);
    z.value.push_back(m.At(f) + std::complex<double>(g(rng), g(rng)));
    z.sigma.push_back(sigma);
  }
  z.method = "test";
  return z;
}

ResonanceFitOptions Options(bool test) {
  ResonanceFitOptions o;
  o.f0_min_hz = 250.0;
  o.f0_max_hz = 700.0;
  o.q_min = 5.0;
  o.q_max = 500.0;
  o.second_mode_test = test;
  return o;
}

const std::string kDrop(names::kSecondModeChi2Drop);

TEST(SecondModeTest, OnlyWhenAsked) {
  const ImpedanceAnalysis a = AnalyzeImpedance(Measure(0.0, 2e-3, 1), Options(false));
  ASSERT_TRUE(a.usable) << a.message;
  EXPECT_EQ(a.values.count(kDrop), 0u);
}

TEST(SecondModeTest, LocalModeDropsChi2FarBeyondTheNoise) {
  double worst_good = 0.0;
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const ImpedanceAnalysis good = AnalyzeImpedance(Measure(0.0, 2e-3, seed), Options(true));
    ASSERT_TRUE(good.usable) << good.message;
    const double d = good.values.at(kDrop).value;
    EXPECT_GE(d, 0.0);
    worst_good = std::max(worst_good, d);
  }
  EXPECT_LT(worst_good, 40.0) << "a one-mode motor: the maximum of a three-parameter chi2 drop";
  // A local mode of 1/40 of the rotor's peak: chi2/dof rises by a few percent only.
  const ImpedanceAnalysis soft = AnalyzeImpedance(Measure(0.015, 2e-3, 1), Options(true));
  ASSERT_TRUE(soft.usable) << soft.message;
  EXPECT_GT(soft.values.at(kDrop).value, 5.0 * worst_good)
      << "chi2/dof " << soft.values.at(std::string(names::kFitChi2PerDof)).value;
}

}  // namespace
}  // namespace eol::analysis
