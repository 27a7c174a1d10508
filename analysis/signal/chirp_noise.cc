#include "analysis/signal/chirp_noise.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <random>
#include <stdexcept>

#include "analysis/signal/fft.h"
#include "analysis/signal/waveform.h"

namespace eol::analysis {

bool ChirpOptions::IsValid(std::string* why) const {
  return ValidPeriodicBand(sample_rate_hz, line_spacing_hz, f_lo_hz, f_hi_hz, peak_v, why);
}

Excitation DesignPeriodicChirp(const ChirpOptions& o) {
  std::string why;
  if (!o.IsValid(&why)) throw std::invalid_argument("chirp: " + why);
  Excitation e;
  e.sample_rate_hz = o.sample_rate_hz;
  e.line_spacing_hz = o.line_spacing_hz;
  e.period_samples = static_cast<std::size_t>(std::llround(o.sample_rate_hz / o.line_spacing_hz));
  e.lines = BandLines(o.f_lo_hz, o.f_hi_hz, o.line_spacing_hz);
  const double period_s = 1.0 / o.line_spacing_hz;
  const double rate_hz_per_s = (o.f_hi_hz - o.f_lo_hz) / period_s;
  e.period_v.resize(e.period_samples);
  for (std::size_t t = 0; t < e.period_samples; ++t) {
    const double ts = static_cast<double>(t) / o.sample_rate_hz;
    const double phase = 2.0 * std::numbers::pi * (o.f_lo_hz * ts + 0.5 * rate_hz_per_s * ts * ts);
    e.period_v[t] = std::sin(phase);
  }
  const double scale = o.peak_v / PeakAbs(e.period_v);
  for (double& v : e.period_v) v *= scale;
  e.crest_factor = CrestFactor(e.period_v);
  return e;
}

bool NoiseOptions::IsValid(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (!(sample_rate_hz > 0.0) || !std::isfinite(sample_rate_hz))
    return fail("sample_rate_hz must be positive");
  if (samples < 16) return fail("samples must be at least 16");
  if (!(f_lo_hz >= 0.0)) return fail("f_lo_hz must not be negative");
  if (!(f_hi_hz > f_lo_hz)) return fail("f_hi_hz must be greater than f_lo_hz");
  if (!(f_hi_hz <= sample_rate_hz / 2.0))
    return fail("f_hi_hz must not exceed the Nyquist frequency");
  const double df = sample_rate_hz / static_cast<double>(samples);
  if (BandLines(std::max(f_lo_hz, df), f_hi_hz, df).empty())
    return fail("the band holds no DFT bin of the record: make it wider or the record longer");
  if (!(peak_v > 0.0) || !std::isfinite(peak_v)) return fail("peak_v must be positive");
  return true;
}

NoiseSignal GenerateBandLimitedNoise(const NoiseOptions& o) {
  std::string why;
  if (!o.IsValid(&why)) throw std::invalid_argument("noise: " + why);
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<double> white(o.samples);
  for (double& v : white) v = normal(rng);
  const RealFft fft(o.samples);
  std::vector<std::complex<double>> spectrum = fft.Forward(white.data());
  const double df = o.sample_rate_hz / static_cast<double>(o.samples);
  for (std::size_t k = 0; k < spectrum.size(); ++k) {
    const double f = static_cast<double>(k) * df;
    if (k == 0 || f < o.f_lo_hz || f > o.f_hi_hz) spectrum[k] = 0.0;
  }
  NoiseSignal out;
  out.sample_rate_hz = o.sample_rate_hz;
  out.samples_v = fft.Inverse(spectrum);
  const double scale = o.peak_v / PeakAbs(out.samples_v);
  for (double& v : out.samples_v) v *= scale;
  out.crest_factor = CrestFactor(out.samples_v);
  return out;
}

}  // namespace eol::analysis
