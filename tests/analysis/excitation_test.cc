// Excitation designs (multisine.h, chirp_noise.h): lines, levels, periodicity and the crest
// factors of analysis/README.md 3 (Schroeder ~1.7, after clipping iterations ~1.5; random phase
// ~3.6; Gaussian noise ~4.7, growing slowly with the record length; chirp sqrt(2)).
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <functional>
#include <numbers>
#include <stdexcept>

#include "analysis/signal/chirp_noise.h"
#include "analysis/signal/fft.h"
#include "analysis/signal/multisine.h"
#include "analysis/signal/waveform.h"

namespace eol::analysis {
namespace {

#define EXPECT_CONTAINS(haystack, needle) \
  EXPECT_PRED_FORMAT2(::testing::IsSubstring, needle, haystack)

// The recipe's excitation: 200-800 Hz at 1 Hz, 8 kHz, 2 V peak.
MultisineOptions Recipe() { return MultisineOptions{}; }

// Power on the bins of `lines` over the power of every bin but DC.
double BandPowerFraction(const std::vector<double>& x, const std::vector<std::size_t>& lines) {
  const RealFft fft(x.size());
  const auto s = fft.Forward(x.data());
  double all = 0.0, band = 0.0;
  for (std::size_t k = 1; k < s.size(); ++k) all += std::norm(s[k]);
  for (std::size_t k : lines) band += std::norm(s[k]);
  return band / all;
}

// Largest step between consecutive samples, counting the wrap from the last to the first.
double MaxStep(const std::vector<double>& x, bool include_wrap) {
  double m = 0.0;
  for (std::size_t t = 1; t < x.size(); ++t) m = std::max(m, std::abs(x[t] - x[t - 1]));
  if (include_wrap) m = std::max(m, std::abs(x.front() - x.back()));
  return m;
}

TEST(MultisineTest, LinesAmplitudesAndLevel) {
  const Excitation e = DesignMultisine(Recipe());
  EXPECT_EQ(e.period_samples, 8000u);
  ASSERT_EQ(e.lines.size(), 601u);
  EXPECT_EQ(e.lines.front(), 200u);
  EXPECT_EQ(e.lines.back(), 800u);
  EXPECT_DOUBLE_EQ(e.LineFrequenciesHz()[10], 210.0);
  EXPECT_NEAR(PeakAbs(e.period_v), 2.0, 1e-12);  // the level is in volts
  // All power on the excited lines, with equal amplitudes.
  const RealFft fft(e.period_samples);
  const auto s = fft.Forward(e.period_v.data());
  const double a0 = std::abs(s[e.lines.front()]);
  for (std::size_t k : e.lines) EXPECT_NEAR(std::abs(s[k]) / a0, 1.0, 1e-9) << "bin " << k;
  EXPECT_GT(BandPowerFraction(e.period_v, e.lines), 1.0 - 1e-12);
}

TEST(MultisineTest, PeriodicAcrossTheWrap) {
  const Excitation e = DesignMultisine(Recipe());
  // A sum of whole-period harmonics continues smoothly into the next period.
  EXPECT_LE(std::abs(e.period_v.front() - e.period_v.back()), MaxStep(e.period_v, false));
  const std::vector<double> three = e.Repeat(3);
  ASSERT_EQ(three.size(), 3 * e.period_samples);
  for (std::size_t t = 0; t < e.period_samples; t += 97)
    EXPECT_EQ(three[t], three[t + 2 * e.period_samples]);
}

TEST(MultisineTest, SchroederCrestFactors) {
  MultisineOptions plain = Recipe();
  plain.crest_iterations = 0;
  const double cf_plain = DesignMultisine(plain).crest_factor;
  const double cf_iter = DesignMultisine(Recipe()).crest_factor;
  std::printf("Schroeder crest factor %.3f, after 300 clipping iterations %.3f\n", cf_plain,
              cf_iter);
  // ~1.7 from near DC; a 4:1 band-pass such as 200-800 Hz gives 1.9 with the plain phases.
  EXPECT_NEAR(cf_plain, 1.8, 0.12);
  EXPECT_NEAR(cf_iter, 1.5, 0.05);
  EXPECT_LT(cf_iter, cf_plain);
}

TEST(MultisineTest, RandomPhaseCrestFactorAndSeed) {
  MultisineOptions o = Recipe();
  o.phases = MultisinePhases::kRandom;
  o.crest_iterations = 0;
  double sum = 0.0;
  const int seeds = 20;
  for (int s = 1; s <= seeds; ++s) {
    o.seed = static_cast<std::uint64_t>(s);
    const Excitation e = DesignMultisine(o);
    EXPECT_NEAR(PeakAbs(e.period_v), 2.0, 1e-12);
    sum += e.crest_factor;
  }
  const double mean_cf = sum / seeds;
  std::printf("random-phase multisine crest factor, mean of %d seeds: %.3f\n", seeds, mean_cf);
  EXPECT_NEAR(mean_cf, 3.7, 0.4);
  o.seed = 3;
  EXPECT_EQ(DesignMultisine(o).period_v, DesignMultisine(o).period_v);  // reproducible
  MultisineOptions other = o;
  other.seed = 4;
  EXPECT_NE(DesignMultisine(o).period_v, DesignMultisine(other).period_v);
  // Clipping iterations help random phases too.
  o.crest_iterations = 300;
  EXPECT_LT(DesignMultisine(o).crest_factor, 2.0);
}

// The current a voltage period drives through `load`.
std::vector<double> CurrentOf(const Excitation& e,
                              const std::function<std::complex<double>(double)>& load) {
  const RealFft fft(e.period_samples);
  const auto u = fft.Forward(e.period_v.data());
  std::vector<std::complex<double>> i(u.size(), 0.0);
  for (std::size_t k : e.lines) i[k] = u[k] / load(static_cast<double>(k) * e.line_spacing_hz);
  return fft.Inverse(i);
}

// |U_k| of the first excited line (all are equal), DFT scaled by 2 / N.
double LineAmplitude(const Excitation& e) {
  const RealFft fft(e.period_samples);
  return 2.0 * std::abs(fft.Forward(e.period_v.data())[e.lines.front()]) /
         static_cast<double>(e.period_samples);
}

TEST(MultisineTest, PhasesForTheCurrentsCrestFactorThroughAnInductiveLoad) {
  // The fast recipe's grid through the winding (0.5 ohm, 2 mH): the current falls 4:1 over
  // the band, and phases that keep the voltage compact make it peaky.
  MultisineOptions o = Recipe();
  o.line_spacing_hz = 8000.0 / 1898.0;
  o.peak_v = 4.0;
  const auto winding = [](double f_hz) {
    return std::complex<double>(0.5, 2.0 * std::numbers::pi * f_hz * 2e-3);
  };
  const Excitation for_voltage = DesignMultisine(o);
  o.crest_load_ohm = winding;
  const Excitation for_current = DesignMultisine(o);
  const double cf_i_voltage_design = CrestFactor(CurrentOf(for_voltage, winding));
  const double cf_i_current_design = CrestFactor(CurrentOf(for_current, winding));
  std::printf(
      "current crest factor: voltage-designed phases %.3f, current-designed %.3f "
      "(voltage's %.3f -> %.3f)\n",
      cf_i_voltage_design, cf_i_current_design, for_voltage.crest_factor, for_current.crest_factor);
  EXPECT_GT(cf_i_voltage_design, 2.4);
  EXPECT_LT(cf_i_current_design, 1.9);
  EXPECT_NEAR(for_current.current_crest_factor, cf_i_current_design, 1e-9);
  // Played from rest, it starts where both channels are near zero (little start transient).
  const std::vector<double> current = CurrentOf(for_current, winding);
  const double start = std::max(std::abs(for_current.period_v.front()) / 4.0,
                                std::abs(current.front()) / PeakAbs(current));
  std::printf("start of the period: %.3f of the larger peak\n", start);
  EXPECT_LT(start, 0.05);
  EXPECT_EQ(for_voltage.current_crest_factor, 0.0);
  // The voltage keeps its contract: peak_v, equal line amplitudes, nothing off the lines.
  EXPECT_NEAR(PeakAbs(for_current.period_v), 4.0, 1e-12);
  EXPECT_NEAR(CrestFactor(for_current.period_v), for_current.crest_factor, 1e-12);
  const RealFft fft(for_current.period_samples);
  const auto s = fft.Forward(for_current.period_v.data());
  const double a0 = std::abs(s[for_current.lines.front()]);
  for (std::size_t k : for_current.lines) EXPECT_NEAR(std::abs(s[k]) / a0, 1.0, 1e-9);
  EXPECT_GT(BandPowerFraction(for_current.period_v, for_current.lines), 1.0 - 1e-12);
  // What it buys: the line amplitude per ampere of peak current, 1.5 times or more.
  const double gain = (LineAmplitude(for_current) / PeakAbs(CurrentOf(for_current, winding))) /
                      (LineAmplitude(for_voltage) / PeakAbs(CurrentOf(for_voltage, winding)));
  std::printf("line amplitude per ampere of peak current: %.2f times\n", gain);
  EXPECT_GT(gain, 1.5);

  o.crest_load_ohm = [](double) { return std::complex<double>(0.0, 0.0); };
  try {
    DesignMultisine(o);
    ADD_FAILURE() << "a zero load was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_CONTAINS(e.what(), "crest_load_ohm is not finite and nonzero");
  }
}

TEST(ChirpTest, ConstantEnvelopeMostPowerInBand) {
  const ChirpOptions o;
  const Excitation e = DesignPeriodicChirp(o);
  EXPECT_EQ(e.period_samples, 8000u);
  EXPECT_EQ(e.lines, BandLines(200.0, 800.0, 1.0));
  EXPECT_NEAR(PeakAbs(e.period_v), 2.0, 1e-12);
  EXPECT_NEAR(e.crest_factor, std::sqrt(2.0), 2e-3);
  const double in_band = BandPowerFraction(e.period_v, e.lines);
  std::printf("periodic chirp: crest factor %.4f, %.4f of the power on the band lines\n",
              e.crest_factor, in_band);
  EXPECT_GT(in_band, 0.98);
  // Continuous across the wrap: sin(phase) starts at 0 and ends near a whole half-cycle.
  EXPECT_LE(std::abs(e.period_v.front() - e.period_v.back()), 1.5 * MaxStep(e.period_v, false));
}

TEST(NoiseTest, BandLimitedSeededAndCrestFactor) {
  NoiseOptions o;
  o.samples = 60 * 8000;  // one minute
  const NoiseSignal n = GenerateBandLimitedNoise(o);
  ASSERT_EQ(n.samples_v.size(), o.samples);
  EXPECT_NEAR(PeakAbs(n.samples_v), 2.0, 1e-12);
  const double df = o.sample_rate_hz / static_cast<double>(o.samples);
  EXPECT_GT(BandPowerFraction(n.samples_v, BandLines(200.0, 800.0, df)), 1.0 - 1e-12);
  std::printf("band-limited Gaussian noise, 60 s: crest factor %.3f\n", n.crest_factor);
  EXPECT_NEAR(n.crest_factor, 4.7, 0.5);
  EXPECT_EQ(GenerateBandLimitedNoise(o).samples_v, n.samples_v);
  o.seed = 2;
  EXPECT_NE(GenerateBandLimitedNoise(o).samples_v, n.samples_v);
}

TEST(ExcitationTest, InvalidOptionsNameTheField) {
  MultisineOptions m = Recipe();
  m.line_spacing_hz = 3.0;  // 8000 / 3 is not whole
  try {
    DesignMultisine(m);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_CONTAINS(e.what(), "whole number of samples per period");
  }
  ChirpOptions c;
  c.f_hi_hz = 4500.0;
  std::string why;
  EXPECT_FALSE(c.IsValid(&why));
  EXPECT_CONTAINS(why, "f_hi_hz must be below the Nyquist frequency");
  NoiseOptions n;
  n.peak_v = -1.0;
  EXPECT_FALSE(n.IsValid(&why));
  EXPECT_CONTAINS(why, "peak_v");
  EXPECT_THROW(GenerateBandLimitedNoise(n), std::invalid_argument);
}

TEST(ExcitationTest, LineSpacingForResonanceKeepsThreeLinesPerBand) {
  const double df = LineSpacingForResonance(390.0, 50.0, 8000.0);
  EXPECT_LE(df, 390.0 / 50.0 / 3.0);
  EXPECT_GT(df, 390.0 / 50.0 / 3.0 * 0.999);
  const double n = 8000.0 / df;
  EXPECT_NEAR(n, std::round(n), 1e-9 * n);
  EXPECT_DOUBLE_EQ(LineSpacingForResonance(390.0, 50.0, 8000.0, 7.8), 1.0);
}

}  // namespace
}  // namespace eol::analysis
