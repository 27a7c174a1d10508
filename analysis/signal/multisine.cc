#include "analysis/signal/multisine.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
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
  if (!(std::isfinite(crest_current_weight_ohm) && crest_current_weight_ohm >= 0.0)) {
    if (why) *why = "crest_current_weight_ohm must be zero or positive";
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

namespace {

// The spectrum of one period with unit-amplitude lines at `phases`.
std::vector<std::complex<double>> LineSpectrum(std::size_t period_samples,
                                               const std::vector<std::size_t>& lines,
                                               const std::vector<double>& phases) {
  std::vector<std::complex<double>> s(period_samples / 2 + 1);
  for (std::size_t i = 0; i < lines.size(); ++i) s[lines[i]] = std::polar(1.0, phases[i]);
  return s;
}

// Unit-amplitude lines with the phases of `s` on `lines`, every other bin zero.
std::vector<std::complex<double>> KeepPhases(const std::vector<std::complex<double>>& s,
                                             const std::vector<std::size_t>& lines) {
  std::vector<std::complex<double>> shaped(s.size());
  for (std::size_t k : lines) {
    const double mag = std::abs(s[k]);
    shaped[k] = mag > 0.0 ? s[k] / mag : std::complex<double>(1.0, 0.0);
  }
  return shaped;
}

// Crest-factor reduction of the voltage: clip the peaks, then put the line amplitudes back
// (keeping the phases the clipping produced) and zero everything outside the excited lines.
// Returns the best period seen.
std::vector<double> ReduceVoltageCrest(const RealFft& fft, const std::vector<std::size_t>& lines,
                                       std::vector<double> x, int iterations) {
  double best_cf = CrestFactor(x);
  std::vector<double> best = x;
  for (int it = 0; it < iterations; ++it) {
    const double clip = 0.9 * PeakAbs(x);
    for (double& v : x) v = std::clamp(v, -clip, clip);
    x = fft.Inverse(KeepPhases(fft.Forward(x.data()), lines));
    const double cf = CrestFactor(x);
    if (cf < best_cf) {
      best_cf = cf;
      best = x;
    }
  }
  return best;
}

// The voltage's and the current's peaks through `load` (per line), for a voltage spectrum u.
struct TwoChannels {
  std::vector<double> u, i;
  double cost = 0.0;  // max(peak u, weight peak i) / rms u (weight 0: peak i / rms u)
};

TwoChannels Drive(const RealFft& fft, const std::vector<std::size_t>& lines,
                  const std::vector<std::complex<double>>& load, double weight_ohm,
                  const std::vector<std::complex<double>>& u_spectrum) {
  std::vector<std::complex<double>> i_spectrum(u_spectrum.size());
  for (std::size_t n = 0; n < lines.size(); ++n)
    i_spectrum[lines[n]] = u_spectrum[lines[n]] / load[n];
  TwoChannels d{fft.Inverse(u_spectrum), fft.Inverse(i_spectrum), 0.0};
  const double peak_i = PeakAbs(d.i);
  d.cost = (weight_ohm > 0.0 ? std::max(PeakAbs(d.u), weight_ohm * peak_i) : peak_i) / Rms(d.u);
  return d;
}

// Crest-factor reduction for both channels: the voltage's line amplitudes stay equal, and the
// line amplitude one period can have within the voltage's limit and the current's (weighed as
// the voltage across weight_ohm) is maximised: each iteration clips whichever channel binds,
// restores its line amplitudes and carries the phases over to the voltage (U_k = Z_k I_k).
std::vector<double> ReduceTwoChannelCrest(const RealFft& fft, const std::vector<std::size_t>& lines,
                                          const std::vector<std::complex<double>>& load,
                                          double weight_ohm,
                                          std::vector<std::complex<double>> u_spectrum,
                                          int iterations, double* current_crest) {
  TwoChannels d = Drive(fft, lines, load, weight_ohm, u_spectrum);
  TwoChannels best = d;
  for (int it = 0; it < iterations; ++it) {
    const bool current_binds = weight_ohm == 0.0 || weight_ohm * PeakAbs(d.i) >= PeakAbs(d.u);
    std::vector<double>& x = current_binds ? d.i : d.u;
    const double clip = 0.9 * PeakAbs(x);
    for (double& v : x) v = std::clamp(v, -clip, clip);
    std::vector<std::complex<double>> s = fft.Forward(x.data());
    if (current_binds)
      for (std::size_t n = 0; n < lines.size(); ++n) s[lines[n]] *= load[n];
    u_spectrum = KeepPhases(s, lines);
    d = Drive(fft, lines, load, weight_ohm, u_spectrum);
    if (d.cost < best.cost) best = d;
  }
  *current_crest = CrestFactor(best.i);
  // Played from rest, the winding's current starts at zero, not at the steady state's i(0): the
  // difference decays with L / R (4 ms) on top of the steady current and can pass the current's
  // peak. A circular shift changes no line amplitude and no peak, so the period starts where
  // both channels are nearest zero (relative to their limits).
  const double u_scale = PeakAbs(best.u);
  const double i_scale = weight_ohm > 0.0 ? u_scale / weight_ohm : PeakAbs(best.i);
  std::size_t start = 0;
  double nearest = std::numeric_limits<double>::infinity();
  for (std::size_t n = 0; n < best.u.size(); ++n) {
    const double v = std::max(std::abs(best.u[n]) / u_scale, std::abs(best.i[n]) / i_scale);
    if (v < nearest) {
      nearest = v;
      start = n;
    }
  }
  std::rotate(best.u.begin(), best.u.begin() + static_cast<std::ptrdiff_t>(start), best.u.end());
  return best.u;
}

}  // namespace

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
  std::vector<double> phases(e.lines.size());
  for (std::size_t i = 0; i < e.lines.size(); ++i) {
    const double idx = static_cast<double>(i + 1);
    phases[i] = o.phases == MultisinePhases::kSchroeder
                    ? -std::numbers::pi * idx * (idx - 1.0) / f_count
                    : uniform(rng);
  }
  std::vector<double> best;
  if (!o.crest_load_ohm) {
    best = ReduceVoltageCrest(fft, e.lines,
                              fft.Inverse(LineSpectrum(e.period_samples, e.lines, phases)),
                              o.crest_iterations);
  } else {
    std::vector<std::complex<double>> load(e.lines.size());
    for (std::size_t i = 0; i < e.lines.size(); ++i) {
      const double f_hz = static_cast<double>(e.lines[i]) * e.line_spacing_hz;
      load[i] = o.crest_load_ohm(f_hz);
      if (!std::isfinite(load[i].real()) || !std::isfinite(load[i].imag()) ||
          std::abs(load[i]) == 0.0)
        throw std::invalid_argument("multisine: crest_load_ohm is not finite and nonzero at " +
                                    std::to_string(f_hz) + " Hz");
    }
    best = ReduceTwoChannelCrest(fft, e.lines, load, o.crest_current_weight_ohm,
                                 LineSpectrum(e.period_samples, e.lines, phases),
                                 o.crest_iterations, &e.current_crest_factor);
  }
  e.crest_factor = CrestFactor(best);
  const double scale = o.peak_v / PeakAbs(best);
  for (double& v : best) v *= scale;
  e.period_v = std::move(best);
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
