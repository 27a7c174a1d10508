// The production line model (analysis/qc/line_population.h): units are reproducible, land where the
// rotor chain says, the fast modal impedance agrees with the chain's exact one, the fast
// measurement's noise has the stated sigma, and the naive |Z| peak is biased as analysis/README.md
// 2 says.
#include <gtest/gtest.h>

#include <cmath>

#include "analysis/bench/naive_rule.h"
#include "analysis/fit/resonance_fit.h"
#include "analysis/model/motor_model.h"
#include "analysis/qc/line_measurement.h"
#include "analysis/qc/line_population.h"

namespace eol::analysis {
namespace {

double FirstModeHz(const LineUnit& u) {
  for (const ChainMode& m : u.motor.chain.Modes())
    if (m.participation > 1e-3 * 1e4) return m.f_hz;  // g_n > 10 / (kg m^2): a visible mode
  return 0.0;
}

TEST(LinePopulation, ReproducibleAndWhereTheChainSays) {
  const RotorChainParams nominal;
  const LineSpread spread;
  const LineUnit a = DrawLineUnit(nominal, spread, DefectClass::kGood, 3, 17);
  const LineUnit b = DrawLineUnit(nominal, spread, DefectClass::kGood, 3, 17);
  EXPECT_EQ(a.motor.r_ohm, b.motor.r_ohm);
  EXPECT_EQ(a.clamp_pressure_bar, b.clamp_pressure_bar);
  EXPECT_GE(a.clamp_pressure_bar, spread.clamp_pressure_lo_bar);
  EXPECT_LE(a.clamp_pressure_bar, spread.clamp_pressure_hi_bar);
  // Good units near 390 Hz, all-soft rotors near the chain's 366 Hz, over 200 units each.
  double good = 0.0, soft = 0.0;
  for (int i = 0; i < 200; ++i) {
    good += FirstModeHz(DrawLineUnit(nominal, spread, DefectClass::kGood, 1, i)) / 200.0;
    soft += FirstModeHz(DrawLineUnit(nominal, spread, DefectClass::kAllSoft, 1, i)) / 200.0;
  }
  EXPECT_NEAR(good, 390.0, 3.0);
  EXPECT_NEAR(soft, 366.0, 4.0);
  // The defect rates are honoured.
  DefectRates rates;
  int defective = 0;
  for (int i = 0; i < 4000; ++i)
    defective += DrawLineUnit(nominal, spread, rates, 5, i).defect != DefectClass::kGood;
  EXPECT_NEAR(defective / 4000.0, rates.Total(), 0.015);
}

TEST(LinePopulation, ModalImpedanceMatchesTheExactChain) {
  const LineUnit u =
      DrawLineUnit(RotorChainParams{}, LineSpread{}, DefectClass::kOneSoftMagnet, 2, 4);
  std::vector<double> f;
  for (double x = 200.0; x <= 800.0; x += 5.0) f.push_back(x);
  const std::vector<std::complex<double>> z = ModalImpedance(u.motor, f);
  double worst = 0.0;
  for (std::size_t k = 0; k < f.size(); ++k) {
    const std::complex<double> exact = u.motor.Impedance(f[k]);
    const std::complex<double> motional =
        exact - u.motor.r_ohm - std::complex<double>(0, 2 * M_PI * f[k] * u.motor.l_h);
    worst = std::max(worst, std::abs(z[k] - exact) / std::max(std::abs(motional), 0.05));
  }
  EXPECT_LT(worst, 0.02);  // proportional damping: within 2 % of the motional part
}

TEST(LineMeasurement, NoiseHasTheStatedSigma) {
  const LineMeasurementSetup setup = MakeLineMeasurement(MultisineOptions{}, 4, 2e-3, 1e-3);
  ASSERT_EQ(setup.freq_hz.size(), 601u);
  MotionalImpedance m{0.5, 2e-3, 0.51, 390.0, 50.0};
  std::vector<std::complex<double>> z;
  for (double f : setup.freq_hz) z.push_back(m.At(f));
  const std::vector<double> expected = LineSigma(setup, z);
  double chi2 = 0.0, var_ratio = 0.0, spread = 0.0;
  int n = 0;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const Frf f = MeasureLineUnit(setup, z, seed);
    for (std::size_t k = 0; k < f.size(); ++k, ++n) {
      chi2 += std::norm(f.value[k] - z[k]) / (expected[k] * expected[k]);
      const double r = std::pow(f.sigma[k] / expected[k], 2);
      var_ratio += r;
      spread += (r - 1.0) * (r - 1.0);
    }
  }
  EXPECT_NEAR(chi2 / n, 1.0, 0.03);  // E|e|^2 = sigma^2
  // The reported sigma is estimated: unbiased in variance, with the scatter of
  // 2 (P - 1) (2 h + 1) = 66 degrees of freedom (variance of the ratio 2 / 66).
  EXPECT_NEAR(var_ratio / n, 1.0, 0.02);
  EXPECT_NEAR(std::sqrt(spread / n), std::sqrt(2.0 / 66.0), 0.05);
  const Frf exact = MeasureLineUnit(setup, z, 1, false);
  EXPECT_EQ(exact.value, z);
  ASSERT_TRUE(exact.has_sigma());
}

TEST(NaiveRule, PeakOfAbsZIsBiasedBelowTheMode) {
  const MotionalImpedance m{0.5, 2e-3, 0.51, 390.0, 50.0};
  Frf z;
  for (double f = 200.0; f <= 800.0; f += 1.0) {
    z.freq_hz.push_back(f);
    z.value.push_back(m.At(f));
  }
  const NaivePeakRule rule;
  const auto peak = NaivePeakHz(z, rule);
  ASSERT_TRUE(peak.has_value());
  EXPECT_LT(*peak, 390.0);
  EXPECT_NEAR(*peak, 388.0, 1.5);
  EXPECT_TRUE(NaivePass(z, rule));
  const MotionalImpedance soft{0.5, 2e-3, 0.51, 350.0, 35.0};
  for (std::size_t k = 0; k < z.size(); ++k) z.value[k] = soft.At(z.freq_hz[k]);
  EXPECT_FALSE(NaivePass(z, rule));
}

}  // namespace
}  // namespace eol::analysis
