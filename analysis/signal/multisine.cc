#include "analysis/signal/multisine.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <random>
#include <stdexcept>

#include "analysis/signal/fft.h"
#include "analysis/signal/waveform.h"

namespace eol::analysis {

bool ValidPeriodicBand(double sample_rate_hz, double line_spacing_hz, double f_lo_hz,
                       double f_hi_hz, double peak_v, std::string* why) {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (!(sample_rate_hz > 0.0) || !std::isfinite(sample_rate_hz))
    return fail("sample_rate_hz must be positive");
  if (!(line_spacing_hz > 0.0) || !std::isfinite(line_spacing_hz))
    return fail("line_spacing_hz must be positive");
  const double n = sample_rate_hz / line_spacing_hz;
  if (std::abs(n - std::round(n)) > 1e-9 * n)
    return fail("sample_rate_hz / line_spacing_hz must be a whole number of samples per period");
  if (!(f_lo_hz > 0.0)) return fail("f_lo_hz must be positive");
  if (!(f_hi_hz > f_lo_hz)) return fail("f_hi_hz must be greater than f_lo_hz");
  if (!(f_hi_hz < sample_rate_hz / 2.0)) return fail("f_hi_hz must be below the Nyquist frequency");
  if (BandLines(f_lo_hz, f_hi_hz, line_spacing_hz).empty())
    return fail("no line of the grid falls inside [f_lo_hz, f_hi_hz]");
  if (!(peak_v > 0.0) || !std::isfinite(peak_v)) return fail("peak_v must be positive");
  return true;
}

bool MultisineOptions::IsValid(std::string* why) const {
  if (!ValidPeriodicBand(sample_rate_hz, line_spacing_hz, f_lo_hz, f_hi_hz, peak_v, why))
    return false;
  if (crest_iterations < 0) {
    if (why) *why = "crest_iterations must not be negative";
    return false;
  }
  return true;
}

std::vector<double> Excitation::Repeat(std::size_t periods) const {
  std::vector<double> out;
  out.reserve(period_v.size() * periods);
  for (std::size_t p = 0; p < periods; ++p) out.insert(out.end(), period_v.begin(), period_v.end());
  return out;
}

std::vector<double> Excitation::LineFrequenciesHz() const {
  std::vector<double> f;
  f.reserve(lines.size());
  for (std::size_t k : lines) f.push_back(static_cast<double>(k) * line_spacing_hz);
  return f;
}

Excitation DesignMultisine(const MultisineOptions& o) {
  std::string why;
  if (!o.IsValid(&why)) throw std::invalid_argument("multisine: " + why);
  Excitation e;
  e.sample_rate_hz = o.sample_rate_hz;
  e.line_spacing_hz = o.line_spacing_hz;
  e.period_samples = static_cast<std::size_t>(std::llround(o.sample_rate_hz / o.line_spacing_hz));
  e.lines = BandLines(o.f_lo_hz, o.f_hi_hz, o.line_spacing_hz);

  const RealFft fft(e.period_samples);
  const double f_count = static_cast<double>(e.lines.size());
  std::mt19937_64 rng(o.seed);
  std::uniform_real_distribution<double> uniform(0.0, 2.0 * std::numbers::pi);
  std::vector<std::complex<double>> spectrum(e.period_samples / 2 + 1);
  for (std::size_t i = 0; i < e.lines.size(); ++i) {
    const double idx = static_cast<double>(i + 1);
    const double phase = o.phases == MultisinePhases::kSchroeder
                             ? -std::numbers::pi * idx * (idx - 1.0) / f_count
                             : uniform(rng);
    spectrum[e.lines[i]] = std::polar(1.0, phase);
  }
  std::vector<double> x = fft.Inverse(spectrum);

  // Crest-factor reduction: clip the peaks, then put the line amplitudes back (keeping the
  // phases the clipping produced) and zero everything outside the excited lines.
  double best_cf = CrestFactor(x);
  std::vector<double> best = x;
  for (int it = 0; it < o.crest_iterations; ++it) {
    const double clip = 0.9 * PeakAbs(x);
    for (double& v : x) v = std::clamp(v, -clip, clip);
    std::vector<std::complex<double>> s = fft.Forward(x.data());
    std::vector<std::complex<double>> shaped(s.size());
    for (std::size_t k : e.lines) {
      const double mag = std::abs(s[k]);
      shaped[k] = mag > 0.0 ? s[k] / mag : std::complex<double>(1.0, 0.0);
    }
    x = fft.Inverse(shaped);
    const double cf = CrestFactor(x);
    if (cf < best_cf) {
      best_cf = cf;
      best = x;
    }
  }
  const double scale = o.peak_v / PeakAbs(best);
  for (double& v : best) v *= scale;
  e.period_v = std::move(best);
  e.crest_factor = best_cf;
  return e;
}

double LineSpacingForResonance(double f0_hz, double q, double sample_rate_hz,
                               double lines_per_band) {
  const double band_hz = f0_hz / q;
  const double max_spacing = band_hz / lines_per_band;
  // Candidate spacings fs/N for whole N: the smallest N with fs/N <= max_spacing.
  const double n = std::ceil(sample_rate_hz / max_spacing - 1e-9);
  return sample_rate_hz / n;
}

}  // namespace eol::analysis
