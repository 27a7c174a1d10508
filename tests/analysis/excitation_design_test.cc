// Excitation designed for time (analysis/signal/excitation_design.h): the chosen record meets
// the bound with the fewest periods, the amplitude stops at the first limit it meets, and
// amplitude buys time as 1 / U^2.
#include "analysis/signal/excitation_design.h"

#include <gtest/gtest.h>

#include <cmath>

#include "analysis/fit/cramer_rao.h"
#include "analysis/signal/fft.h"

namespace eol::analysis {
namespace {

MultisineOptions Band() {
  MultisineOptions o;
  o.sample_rate_hz = 8000;
  o.f_lo_hz = 200;
  o.f_hi_hz = 800;
  o.line_spacing_hz = 1;
  o.peak_v = 2;
  o.crest_iterations = 30;
  return o;
}

ExcitationRequirement Requirement() {
  ExcitationRequirement r;
  r.sigma_f0_hz = 0.01;
  r.nominal = {.r_ohm = 0.5, .l_h = 2e-3, .rp_ohm = 0.53, .f0_hz = 390, .q = 50};
  r.noise_v_rms = 2e-3;
  r.noise_a_rms = 1e-3;
  r.max_peak_v = 6;
  r.current_full_scale_a = 2;
  return r;
}

TEST(ExcitationDesign, MeetsTheBoundWithTheFewestPeriods) {
  const ExcitationRequirement r = Requirement();
  const ExcitationDesign d = DesignExcitationForTime(Band(), r);
  ASSERT_TRUE(d.usable) << d.message;
  const ExcitationCandidate& c = d.chosen;
  EXPECT_GE(c.periods, r.min_periods);
  const double at = PredictedSigmaF0Hz(d.excitation, c.periods, r);
  EXPECT_LE(at, r.sigma_f0_hz * (1 + 1e-6));
  EXPECT_NEAR(at, c.sigma_f0_hz, 1e-9 + 1e-6 * at);
  if (c.periods > r.min_periods) {
    EXPECT_GT(PredictedSigmaF0Hz(d.excitation, c.periods - 1, r), r.sigma_f0_hz);
  }
  if (c.periods == r.min_periods) {  // at the floor: the amplitude is lowered to just meet it
    EXPECT_EQ(c.amplitude_limited_by, "requirement");
    EXPECT_NEAR(at, r.sigma_f0_hz, 1e-6 * r.sigma_f0_hz);
  }
  // The grid resolves the mode: at least two lines across f0 / Q.
  EXPECT_LE(c.line_spacing_hz, r.nominal.f0_hz / r.nominal.q / 2 + 1e-9);
  EXPECT_NEAR(c.record_s, static_cast<double>(c.periods) / c.line_spacing_hz, 1e-12);
  // The shortest of the candidates that meet it.
  for (const ExcitationCandidate& other : d.candidates) {
    if (other.meets) {
      EXPECT_GE(other.record_s, c.record_s - 1e-9);
    }
  }
}

TEST(ExcitationDesign, AmplitudeStopsAtTheFirstLimit) {
  ExcitationRequirement r = Requirement();
  r.sigma_f0_hz = 0.005;  // more than the fewest periods at every amplitude below
  r.current_full_scale_a = 1e9;
  ExcitationDesign d = DesignExcitationForTime(Band(), r);
  ASSERT_TRUE(d.usable) << d.message;
  EXPECT_EQ(d.chosen.amplitude_limited_by, "max_peak_v");
  EXPECT_NEAR(d.chosen.peak_v, r.max_peak_v, 1e-12);

  // A small current channel: the peak current sits at 0.8 of its full scale. Checked against
  // the current synthesised here from the designed voltage and the nominal impedance.
  r.current_full_scale_a = 0.5;
  d = DesignExcitationForTime(Band(), r);
  ASSERT_TRUE(d.usable) << d.message;
  EXPECT_EQ(d.chosen.amplitude_limited_by, "current_full_scale");
  EXPECT_NEAR(d.chosen.current_peak_a, kCurrentHeadroom * 0.5, 1e-9);
  const Excitation ex = DesignMultisine(d.excitation);
  const RealFft fft(ex.period_samples);
  const auto u = fft.Forward(ex.period_v.data());
  std::vector<std::complex<double>> i(u.size(), 0.0);
  for (std::size_t k : ex.lines) {
    const double w = 2 * M_PI * static_cast<double>(k) * ex.line_spacing_hz;
    const std::complex<double> s(0, w);
    const MotionalImpedance& m = r.nominal;
    const double w0 = 2 * M_PI * m.f0_hz;
    const std::complex<double> z = m.r_ohm + s * m.l_h + m.rp_ohm / (1.0 + m.q * (s / w0 + w0 / s));
    i[k] = u[k] / z;
  }
  double peak = 0;
  for (double a : fft.Inverse(i)) peak = std::max(peak, std::abs(a));
  EXPECT_NEAR(peak, kCurrentHeadroom * 0.5, 1e-6);

  // An rms limit on the voltage.
  r.current_full_scale_a = 1e9;
  r.max_v_rms = 1.0;
  d = DesignExcitationForTime(Band(), r);
  ASSERT_TRUE(d.usable) << d.message;
  EXPECT_EQ(d.chosen.amplitude_limited_by, "max_v_rms");
  EXPECT_NEAR(d.chosen.v_rms, 1.0, 1e-9);
}

TEST(ExcitationDesign, PhasesForTheCurrentCarryMoreInformationThroughTheSameCurrentRange) {
  // The fast recipe's case: the current channel limits the amplitude. Phases that keep the
  // current compact let the voltage rise until the current's peak is the same again.
  ExcitationRequirement r = Requirement();
  r.sigma_f0_hz = 1e-4;  // far beyond reach: no candidate lowers its amplitude
  r.max_peak_v = 10;
  r.lines_per_half_power_band = 1.85;
  r.max_record_s = 1e6;
  MultisineOptions base = Band();
  base.crest_iterations = 300;
  const ExcitationDesign voltage = DesignExcitationForTime(base, r);
  base.crest_load_ohm = [m = r.nominal](double f_hz) { return m.At(f_hz); };
  base.crest_current_weight_ohm = r.max_peak_v / (kCurrentHeadroom * r.current_full_scale_a);
  const ExcitationDesign current = DesignExcitationForTime(base, r);
  ASSERT_TRUE(voltage.usable && current.usable);
  const ExcitationCandidate& v = voltage.candidates.front();
  const ExcitationCandidate& c = current.candidates.front();
  ASSERT_DOUBLE_EQ(v.line_spacing_hz, c.line_spacing_hz);
  EXPECT_EQ(v.amplitude_limited_by, "current_full_scale");
  EXPECT_LE(c.current_peak_a, kCurrentHeadroom * r.current_full_scale_a * (1 + 1e-9));
  const double information = std::pow(v.sigma_f0_one_period_hz / c.sigma_f0_one_period_hz, 2);
  std::printf(
      "%.4f Hz lines: voltage-crest phases %.2f V peak (%s), current-crest %.2f V (%s); "
      "information x %.2f\n",
      v.line_spacing_hz, v.peak_v, v.amplitude_limited_by.c_str(), c.peak_v,
      c.amplitude_limited_by.c_str(), information);
  EXPECT_GT(information, 2.0);
}

TEST(ExcitationDesign, AmplitudeBuysTimeAsOneOverUSquared) {
  ExcitationRequirement r = Requirement();
  r.current_full_scale_a = 1e9;
  r.sigma_f0_hz = 0.004;  // many periods, so rounding up is a small share
  r.max_peak_v = 2;
  const ExcitationDesign low = DesignExcitationForTime(Band(), r);
  r.max_peak_v = 6;
  const ExcitationDesign high = DesignExcitationForTime(Band(), r);
  ASSERT_TRUE(low.usable && high.usable);
  // On the same grid (the first candidate of each: the coarsest) the bound of one period goes
  // as 1 / U, and the periods needed as 1 / U^2.
  const ExcitationCandidate& l = low.candidates.front();
  const ExcitationCandidate& h = high.candidates.front();
  ASSERT_EQ(l.line_spacing_hz, h.line_spacing_hz);
  EXPECT_NEAR(l.sigma_f0_one_period_hz / h.sigma_f0_one_period_hz, 3.0, 1e-6);
  EXPECT_NEAR(l.record_s / h.record_s, 9.0, 0.7);
}

TEST(ExcitationDesign, ImpossibleRequirementIsNotUsable) {
  ExcitationRequirement r = Requirement();
  r.sigma_f0_hz = 1e-7;
  r.max_record_s = 5;
  const ExcitationDesign d = DesignExcitationForTime(Band(), r);
  EXPECT_FALSE(d.usable);
  EXPECT_NE(d.message.find("reaches std(f0)"), std::string::npos) << d.message;
}

TEST(ExcitationDesign, InvalidRequirementNamesTheField) {
  ExcitationRequirement r = Requirement();
  r.noise_a_rms = 0;
  EXPECT_THROW(
      {
        try {
          DesignExcitationForTime(Band(), r);
        } catch (const std::invalid_argument& e) {
          EXPECT_NE(std::string(e.what()).find("noise_a_rms"), std::string::npos) << e.what();
          throw;
        }
      },
      std::invalid_argument);
  r = Requirement();
  r.verdict_margin_hz = 0.015;  // margin / z = 0.005 < sigma_f0_hz
  EXPECT_NEAR(r.RequiredSigmaF0Hz(), 0.005, 1e-12);
}

}  // namespace
}  // namespace eol::analysis
