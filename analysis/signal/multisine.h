// Periodic broadband excitation: multisine with crest-factor reduction.
//
// One period lasts 1/line_spacing_hz and holds period_samples = sample_rate_hz/line_spacing_hz
// samples (must be a whole number). Lines are the DFT bins k (f_k = k * line_spacing_hz) in
// [f_lo_hz, f_hi_hz]; all get the same amplitude. Phases (F lines, i = 1..F):
//   Schroeder:  phi_i = -pi i (i - 1) / F     crest factor about 1.7 for a band from near DC,
//                                             1.9 for the recipe's 200-800 Hz (analysis/README.md
//                                             3)
//   random:     phi_i uniform on [0, 2 pi)    crest factor about 3.6-3.9 (seeded)
// Clipping iterations (clip in time at 0.9 of the peak, restore the line amplitudes in
// frequency, keep the phases the clipping produced, zero every other bin) converge slowly:
// Schroeder 200-800 Hz reaches 1.64 after 30, 1.55 after 100 and 1.52 after 300 (about 60 ms);
// the best period seen is kept. The period is scaled to a peak of peak_v volts.
//
// Crest factor of the current too (crest_load_ohm set): a motor's current I_k = U_k / Z(f_k)
// falls with frequency (the winding's inductance), and phases that make a flat-amplitude voltage
// compact make that current peaky (crest factor about 3 for the fast recipe's 142 lines
// through the nominal motor, against 1.55 for the voltage). When the current channel's range
// limits the amplitude, what matters is the larger of the two peaks, each against its limit:
// max(peak u, w peak i) with w = the voltage's limit / the current's (crest_current_weight_ohm;
// 0: the current's peak alone). Each clipping iteration clips whichever channel binds, restores
// its line amplitudes keeping the phases (U_k = Z_k I_k for the current) and keeps the voltage's
// line amplitudes equal; the best period seen (the smallest max(peak u, w peak i) / rms u) is
// kept and scaled to peak_v as before. For the fast recipe's limits (8 V, 1.6 A) the same
// current range then carries about 1.6 times the line amplitude (about 2.6 times the
// information; analysis/README.md, Excitation designed for time).
#pragma once

#include <complex>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace eol::analysis {

enum class MultisinePhases { kSchroeder, kRandom };

struct MultisineOptions {
  double sample_rate_hz = 8000.0;
  double line_spacing_hz = 1.0;
  double f_lo_hz = 200.0;
  double f_hi_hz = 800.0;
  double peak_v = 2.0;         // peak of the designed period, volts at the amplifier output
  int crest_iterations = 300;  // 0: the plain phases
  MultisinePhases phases = MultisinePhases::kSchroeder;
  std::uint64_t seed = 1;  // of the random phases (kRandom only)
  // The load (ohm at f_hz) whose current's peak the phases keep low beside the voltage's (see
  // above); empty: the voltage's crest factor alone. Finite and nonzero on the lines.
  std::function<std::complex<double>(double f_hz)> crest_load_ohm;
  double crest_current_weight_ohm = 0.0;  // w above (>= 0; with crest_load_ohm only)

  bool IsValid(std::string* why) const;
};

struct Excitation {
  double sample_rate_hz = 0.0;
  double line_spacing_hz = 0.0;
  std::size_t period_samples = 0;
  std::vector<double> period_v;    // one period, volts
  std::vector<std::size_t> lines;  // excited DFT bins of one period, increasing
  double crest_factor = 0.0;       // peak / rms of one period
  // Peak / rms of the current through crest_load_ohm (0 when the design had no load).
  double current_crest_factor = 0.0;

  // The period repeated `periods` times (what the amplifier plays).
  std::vector<double> Repeat(std::size_t periods) const;
  std::vector<double> LineFrequenciesHz() const;
};

// The checks every periodic excitation shares: positive finite rate, spacing and peak, a whole
// number of samples per period, 0 < f_lo < f_hi < Nyquist and at least one line in the band.
// Returns false with the reason (naming the field) in *why.
bool ValidPeriodicBand(double sample_rate_hz, double line_spacing_hz, double f_lo_hz,
                       double f_hi_hz, double peak_v, std::string* why);

// Throws std::invalid_argument with the reason when !options.IsValid().
Excitation DesignMultisine(const MultisineOptions& options);

// Largest line spacing that keeps at least `lines_per_band` lines inside the half-power band
// f0/q of the narrowest expected resonance, rounded down to a divisor of sample_rate_hz.
double LineSpacingForResonance(double f0_hz, double q, double sample_rate_hz,
                               double lines_per_band = 3.0);

}  // namespace eol::analysis
