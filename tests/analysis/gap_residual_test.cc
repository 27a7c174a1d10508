// The gap metric's building blocks: the chi-square z, the band search, the noise estimate
// and pooling (analysis/gap/residual.h, noise.h), the calibration (calibration.h) and the
// prediction carried to a second simulation (prediction.h). Fixed seeds.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <span>

#include "analysis/gap/calibration.h"
#include "analysis/gap/effect_fit.h"
#include "analysis/gap/noise.h"
#include "analysis/gap/prediction.h"
#include "analysis/gap/residual.h"
#include "analysis/sim/population.h"

namespace eol::analysis {
namespace {

// chi2 per line of 2 |r|^2 with r circular complex Gaussian of unit variance (dof 2 each).
std::vector<double> NoiseChi2(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::exponential_distribution<double> e(0.5);  // chi2 with 2 dof: mean 2
  std::vector<double> c(n);
  for (double& x : c) x = e(rng);
  return c;
}

std::vector<double> Freqs(std::size_t n) {
  std::vector<double> f(n);
  for (std::size_t k = 0; k < n; ++k) f[k] = 200.0 + static_cast<double>(k);
  return f;
}

TEST(GapResidual, ChiSquareZ) {
  EXPECT_NEAR(ChiSquareZ(1200.0, 1200.0), 0.0, 0.02);
  // chi2 = d + 3 sqrt(2 d) is 2.90 sigma, not 3: the chi-square is skewed (exact tail
  // probability 1.87e-3 for d = 1200; Wilson-Hilferty gives z = 2.899).
  EXPECT_NEAR(ChiSquareZ(1200.0 + 3.0 * std::sqrt(2400.0), 1200.0), 2.90, 0.01);
  EXPECT_LT(ChiSquareZ(800.0, 1200.0), -5.0);
  EXPECT_EQ(ChiSquareZ(1.0, 0.0), 0.0);
}

TEST(GapResidual, NoBandInNoiseANarrowOneAtAPeakAOneWideForAnOffset) {
  const std::size_t n = 601;
  const std::vector<double> f = Freqs(n), dof(n, 2.0);
  BandSearchOptions o;
  for (std::uint64_t seed = 1; seed <= 5; ++seed)
    EXPECT_TRUE(FindGapBands(f, NoiseChi2(n, seed), dof, o).empty()) << seed;
  // A peak of excess at 400-409 Hz.
  std::vector<double> c = NoiseChi2(n, 7);
  for (std::size_t k = 200; k < 210; ++k) c[k] += 60.0;
  std::vector<GapBand> b = FindGapBands(f, c, dof, o);
  ASSERT_FALSE(b.empty());
  // Edges are fuzzy by a few lines: a noise line with some excess still raises the z.
  EXPECT_NEAR(b[0].f_lo_hz, 400.0, 8.0);
  EXPECT_NEAR(b[0].f_hi_hz, 409.0, 8.0);
  EXPECT_GT(b[0].significance, 20.0);
  // A uniform excess: one broad band (its ends move with the noise's random walk).
  c = NoiseChi2(n, 8);
  for (double& x : c) x *= 1.3;
  b = FindGapBands(f, c, dof, o);
  ASSERT_EQ(b.size(), 1u);
  EXPECT_GT(b[0].f_hi_hz - b[0].f_lo_hz, 300.0);
}

TEST(GapResidual, NoiseEstimateAndPooling) {
  MotionalImpedance m{0.5, 2e-3, 0.51, 390.0, 50.0};
  Frf h = m.Evaluate(Freqs(601));
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g(0.0, std::sqrt(0.5));
  std::vector<double> truth;
  for (std::size_t k = 0; k < h.size(); ++k) {
    truth.push_back(1e-3 * std::abs(h.value[k]));  // noise proportional to |H|
    h.value[k] += truth.back() * std::complex<double>(g(rng), g(rng));
  }
  const std::vector<double> est = EstimateLineSigma(h);
  double ratio2 = 0.0;
  for (std::size_t k = 0; k < h.size(); ++k) ratio2 += est[k] * est[k] / (truth[k] * truth[k]);
  EXPECT_NEAR(std::sqrt(ratio2 / static_cast<double>(h.size())), 1.0, 0.1);
  // Pooling keeps the scale and smooths: a sigma with scatter becomes steadier.
  h.sigma = truth;
  for (std::size_t k = 0; k < h.size(); k += 2) h.sigma[k] *= 1.5;
  const std::vector<double> pooled = PoolLineSigma(h, 3);
  for (std::size_t k = 10; k + 10 < h.size(); ++k)
    EXPECT_NEAR(pooled[k] / truth[k], std::sqrt((1.0 + 2.25) / 2.0), 0.1) << k;
  EXPECT_EQ(PoolLineSigma(h, 0), h.sigma);
}

TEST(GapResidual, NeighbourMagnitudeIsExactForAQuadraticAndLeavesTheLineOutWithinItsNoise) {
  Frf h;
  h.freq_hz = Freqs(12);
  for (double f : h.freq_hz) {
    const double x = f - 205.0;
    h.value.push_back({3.0 + 0.2 * x + 0.05 * x * x, 1.0 - 0.1 * x});
  }
  const std::vector<double> noise(h.size(), 1e-4);  // relative variance: 1 % sigma
  const std::vector<double> exact = NeighbourMagnitude(h, noise);
  for (std::size_t k = 2; k + 2 < h.size(); ++k) {
    EXPECT_NEAR(exact[k], std::abs(h.value[k]), 1e-9) << k;
  }
  // A step on line 6 within its noise moves its neighbours' estimates, not its own.
  Frf bumped = h;
  bumped.value[6] *= 1.02;
  const std::vector<double> near = NeighbourMagnitude(bumped, noise);
  EXPECT_DOUBLE_EQ(near[6], exact[6]);
  EXPECT_GT(std::abs(near[5] - exact[5]), 1e-3);
  // A spike far beyond the noise (a mode one line wide, a glitch) keeps its own magnitude.
  Frf spiked = h;
  spiked.value[6] += 100.0;
  const std::vector<double> mag = NeighbourMagnitude(spiked, noise);
  EXPECT_DOUBLE_EQ(mag[6], std::abs(spiked.value[6]));
  EXPECT_DOUBLE_EQ(mag[0], std::abs(spiked.value[0]));  // the end lines: their own
}

// The estimated sigma must not follow the line's own noise draw: with sigma proportional to
// the line's |H_k|, the lines whose noise pulled |H| low weigh most and the 1/sigma^2-weighted
// mean of the relative error along H is about -eps^2 (-0.09 here, ten standard errors).
TEST(GapResidual, EstimatedSigmaDoesNotWeighTheLinesByTheirOwnNoise) {
  MotionalImpedance m{0.5, 2e-3, 0.51, 390.0, 50.0};
  const Frf clean = m.Evaluate(Freqs(601));
  Frf h = clean;
  std::mt19937_64 rng(11);
  const double eps = 0.3;
  std::normal_distribution<double> g(0.0, eps * std::sqrt(0.5));
  for (auto& v : h.value) v += std::abs(v) * std::complex<double>(g(rng), g(rng));
  // The 1/sigma^2-weighted mean of the relative error along H (in units of the true |H|).
  const auto weighted_error = [&](const std::vector<double>& sigma) {
    double num = 0.0, den = 0.0;
    for (std::size_t k = 0; k < h.size(); ++k) {
      const double along = std::real((h.value[k] - clean.value[k]) / clean.value[k]);
      const double w = std::norm(clean.value[k]) / (sigma[k] * sigma[k]);
      num += w * along;
      den += w;
    }
    return num / den;
  };
  const double standard_error = eps * std::sqrt(0.5 / static_cast<double>(h.size()));
  const double estimated = weighted_error(EstimateLineSigma(h));
  EXPECT_LT(std::abs(estimated), 3.0 * standard_error) << estimated;
  // Pooling converts back the same way.
  h.sigma.assign(h.size(), 0.0);
  for (std::size_t k = 0; k < h.size(); ++k) h.sigma[k] = eps * std::abs(h.value[k]);
  const double pooled = weighted_error(PoolLineSigma(h, 5));
  EXPECT_LT(std::abs(pooled), 3.0 * standard_error) << pooled;
}

// A ratio of period means, Z = mean U / mean I, over P = 8 periods with noise on both
// channels (the voltage's s_u, the current's s_i per period), and its sigma from the periods
// (analysis/README.md 3). On an inductive Z from 1 to 38 ohm the voltage's noise dominates where
// |Z| < s_u / s_i = 20 ohm and the current's above. The per-line form (ChooseResidualForm)
// takes the admittance form above the crossing and the impedance form below. The impedance
// form is biased low on the current's lines (a line whose current came out high has a low |Z|
// and a small sigma), the admittance form high on the voltage's; the form chosen per line
// leaves at most half of either bias in the true model's residual along the curve.
TEST(GapResidual, PerLineFormFollowsTheNoisyChannelAndLeavesTheTrueModelUnbiased) {
  const std::size_t n = 2400, periods = 8;
  const double v = 1.0, s_u = 0.5, s_i = 0.025, crossing = s_u / s_i;
  std::vector<std::complex<double>> z(n);
  GapUnit u;
  u.sigma_dof = 2.0 * (periods - 1);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g(0.0, std::sqrt(0.5));
  for (std::size_t k = 0; k < n; ++k) {
    const double f = 50.0 + 0.8125 * static_cast<double>(k);
    z[k] = {1.0, 2.0 * std::numbers::pi * f * 3e-3};
    std::vector<std::complex<double>> up(periods), ip(periods);
    std::complex<double> um, im;
    for (std::size_t p = 0; p < periods; ++p) {
      up[p] = v + s_u * std::complex<double>(g(rng), g(rng));
      ip[p] = v / z[k] + s_i * std::complex<double>(g(rng), g(rng));
      um += up[p] / static_cast<double>(periods);
      im += ip[p] / static_cast<double>(periods);
    }
    double vu = 0.0, vi = 0.0;
    std::complex<double> cui;
    for (std::size_t p = 0; p < periods; ++p) {
      vu += std::norm(up[p] - um) / (periods - 1.0);
      vi += std::norm(ip[p] - im) / (periods - 1.0);
      cui += (up[p] - um) * std::conj(ip[p] - im) / (periods - 1.0);
    }
    const std::complex<double> zm = um / im;
    const double var =
        std::norm(zm) / periods *
        (vu / std::norm(um) + vi / std::norm(im) - 2.0 * std::real(cui / (um * std::conj(im))));
    u.freq_hz.push_back(f);
    u.value.push_back(zm);
    u.sigma.push_back(std::sqrt(var));
  }
  ChooseResidualForm(u, true, ResidualForm::kAuto);
  ASSERT_EQ(u.admittance_line.size(), n);
  EXPECT_FALSE(u.admittance);
  int wrong = 0, sides = 0;
  for (std::size_t k = 0; k < n; ++k) {
    if (std::abs(z[k]) < 0.8 * crossing || std::abs(z[k]) > 1.25 * crossing) {
      ++sides;
      wrong += u.admittance_line[k] != (std::abs(z[k]) > crossing) ? 1 : 0;
    }
  }
  EXPECT_LE(wrong, sides / 20) << wrong << " of " << sides;

  // The true model's residual along the curve (Re of r over the direction of +dZ in the
  // line's form), averaged over the current's lines or the voltage's, in standard errors.
  const auto mean_along = [&](const GapUnit& formed, bool current_lines) {
    double sum = 0.0;
    int lines = 0;
    for (std::size_t k = 0; k < n; ++k) {
      if ((std::abs(z[k]) > crossing) != current_lines) continue;
      const std::complex<double> r = LineResidual(formed, k, z[k]);
      const std::complex<double> unit_dir = z[k] / std::abs(z[k]);
      const bool y =
          formed.admittance || (k < formed.admittance_line.size() && formed.admittance_line[k]);
      sum += y ? -std::real(r * unit_dir) : std::real(r * std::conj(unit_dir));
      ++lines;
    }
    return sum / lines / std::sqrt(0.5 / lines);
  };
  GapUnit every = u;
  ChooseResidualForm(every, true, ResidualForm::kImpedance);
  const double z_on_current = mean_along(every, true);
  ChooseResidualForm(every, true, ResidualForm::kAdmittance);
  const double y_on_voltage = mean_along(every, false);
  EXPECT_LT(z_on_current, -5.0);
  EXPECT_GT(y_on_voltage, 5.0);
  // What is left on each side is the other channel's noise (eps about 0.18 on every line).
  EXPECT_LT(std::abs(mean_along(u, true)), 0.5 * std::abs(z_on_current)) << mean_along(u, true);
  EXPECT_LT(std::abs(mean_along(u, false)), 0.5 * y_on_voltage) << mean_along(u, false);
  // A flat |H| gives no lever to tell the channels apart: the impedance form.
  GapUnit flat = u;
  for (std::size_t k = 0; k < n; ++k) flat.value[k] = 5.0 * u.value[k] / std::abs(u.value[k]);
  ChooseResidualForm(flat, true, ResidualForm::kAuto);
  EXPECT_FALSE(flat.admittance);
  EXPECT_TRUE(flat.admittance_line.empty());
  // A smooth sigma (estimated, not the line's own) keeps the impedance form.
  every.sigma_smooth = true;
  ChooseResidualForm(every, true, ResidualForm::kAuto);
  EXPECT_FALSE(every.admittance);
  EXPECT_TRUE(every.admittance_line.empty());
}

TEST(GapResidual, TrigammaKnownValues) {
  const double pi2 = std::numbers::pi * std::numbers::pi;
  EXPECT_NEAR(Trigamma(1.0), pi2 / 6.0, 1e-10);
  EXPECT_NEAR(Trigamma(0.5), pi2 / 2.0, 1e-10);
  EXPECT_NEAR(Trigamma(7.0), pi2 / 6.0 - (1.0 + 1.0 / 4 + 1.0 / 9 + 1.0 / 16 + 1.0 / 25 + 1.0 / 36),
              1e-10);
  EXPECT_NEAR(Trigamma(500.0),
              1.0 / 500.0 + 0.5 / (500.0 * 500.0) + 1.0 / (6.0 * 500.0 * 500.0 * 500.0), 1e-14);
}

// sigma^2 = sigma_k^2 chi2_nu / nu on a sigma_k that follows a resonance: nu read back from
// the scatter; a sigma without scatter reads as exact; too few lines or a bad value: exact.
TEST(GapResidual, SigmasDegreesOfFreedomFromItsScatter) {
  MotionalImpedance m{0.5, 2e-3, 0.51, 390.0, 50.0};
  const Frf h = m.Evaluate(Freqs(781));
  std::mt19937_64 rng(5);
  for (double nu : {6.0, 14.0, 66.0}) {
    std::chi_squared_distribution<double> chi2(nu);
    std::vector<double> smooth, sigma;
    for (std::size_t k = 0; k < h.size(); ++k) {
      smooth.push_back(1e-3 * std::abs(h.value[k]));
      sigma.push_back(smooth.back() * std::sqrt(chi2(rng) / nu));
    }
    EXPECT_NEAR(EstimateSigmaDof(sigma), nu, 0.2 * nu) << nu;
    EXPECT_EQ(EstimateSigmaDof(smooth), 0.0);
    sigma[100] = std::numeric_limits<double>::quiet_NaN();
    EXPECT_EQ(EstimateSigmaDof(sigma), 0.0);
    EXPECT_EQ(EstimateSigmaDof(std::span<const double>(sigma).first(19)), 0.0);
  }
  // Scatter that says fewer than 5 degrees of freedom: 5, the least the F test is written for.
  std::vector<double> wild;
  std::chi_squared_distribution<double> chi1(1.0);
  for (int k = 0; k < 200; ++k) wild.push_back(std::sqrt(chi1(rng)));
  EXPECT_EQ(EstimateSigmaDof(wild), kMinEstimatedSigmaDof);
}

TEST(GapCalibration, RigidShaftAndMotionalNominalsAreRecovered) {
  Frf m;
  m.quantity = Quantity::kMobility;
  const RigidShaftMobility rigid{100.0, 13.8};
  for (double f = 11.0; f <= 250.0; f += 1.0) {
    m.freq_hz.push_back(f);
    m.value.push_back(rigid.At(f));
  }
  CalibrationSummary c = CalibrateNominal(m, CalibrationOptions{});
  ASSERT_TRUE(c.usable) << c.message;
  EXPECT_NEAR(c.nominal.rigid.gain_rad_per_s2_per_a, 100.0, 1e-6);
  EXPECT_NEAR(c.nominal.rigid.damping_per_s, 13.8, 1e-6);
  const MotionalImpedance z{0.5, 2e-3, 0.28, 706.0, 50.0};
  CalibrationOptions o;
  o.inertia_kg_m2 = 1e-4;
  c = CalibrateNominal(z.Evaluate(Freqs(601)), o);
  ASSERT_TRUE(c.usable) << c.message;
  EXPECT_NEAR(c.nominal.motional.f0_hz, 706.0, 1e-6);
  EXPECT_LT(c.misfit_rel_rms, 1e-9);
  EXPECT_EQ(c.nominal.inertia_kg_m2, 1e-4);
  Frf bad = z.Evaluate(Freqs(5));
  EXPECT_FALSE(CalibrateNominal(bad, o).usable);
}

// The paper's numbers: the fixture found against the rigid 706 Hz rotor carried over to the
// poorly cemented rotor (529 Hz rigid) lands where analysis::ClampedRotor puts it (~350 Hz).
TEST(GapPrediction, FixtureCarriesOverToTheDefectiveRotor) {
  const MotorPopulation p;
  const double rigid = std::numeric_limits<double>::infinity();
  auto nominal = [&](bool defective) {
    ClampedRotor r{p.inertia_kg_m2, p.KRotorNmPerRad(defective), rigid,
                   defective ? p.q_defect : p.q_good, p.transmission_nm_per_a};
    NominalNetwork n;
    n.motional = r.Electrical(p.r_ohm, p.l_h);
    n.inertia_kg_m2 = p.inertia_kg_m2;
    return n;
  };
  const NominalNetwork good = nominal(false), defect = nominal(true);
  const double kappa = p.KFixtureNmPerRad() / p.KRotorNmPerRad(false);
  RankedEffect fit;
  fit.effect = "fixture_compliance";
  fit.effects = {{EffectKind::kFixtureCompliance, {kappa, FixtureLossKeepingQ(kappa, 50.0)}}};
  fit.params = {{"k_fixture_ratio", "1", kappa, 1e-4 * kappa},
                {"fixture_loss_factor", "1", 0.024, 1e-4}};
  const PredictionSummary s = PredictWithEffects(good, fit, defect, Freqs(601));
  ASSERT_TRUE(s.usable) << s.message;
  ClampedRotor truth{p.inertia_kg_m2, p.KRotorNmPerRad(true), p.KFixtureNmPerRad(), p.q_defect,
                     p.transmission_nm_per_a};
  EXPECT_NEAR(s.f0_simulated_hz, 529.0, 1e-6);
  EXPECT_NEAR(s.f0_predicted_hz, truth.NaturalFrequencyHz(), 0.2);
  EXPECT_GT(s.sigma_f0_hz, 0.0);
  EXPECT_LT(s.sigma_f0_hz, 0.1);
  // Equal inertias: the ratio rule without J gives the same.
  NominalNetwork good_no_j = good, defect_no_j = defect;
  good_no_j.inertia_kg_m2 = defect_no_j.inertia_kg_m2 = 0.0;
  EXPECT_NEAR(PredictWithEffects(good_no_j, fit, defect_no_j, Freqs(601)).f0_predicted_hz,
              s.f0_predicted_hz, 1e-6);
}

}  // namespace
}  // namespace eol::analysis
