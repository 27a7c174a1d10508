// Periodic broadband excitation: Schroeder multisine with crest-factor reduction.
//
// One period lasts 1/line_spacing_hz and holds period_samples = sample_rate_hz/line_spacing_hz
// samples (must be a whole number). Lines are the DFT bins k (f_k = k * line_spacing_hz) in
// [f_lo_hz, f_hi_hz]; all get the same amplitude. Schroeder phases phi_k = -pi k (k-1) / F
// give a crest factor of about 1.7; clipping iterations (clip in time, restore the line
// amplitudes in frequency, keep the phases) bring it to about 1.5.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace eol::analysis {

struct MultisineOptions {
  double sample_rate_hz = 8000.0;
  double line_spacing_hz = 1.0;
  double f_lo_hz = 200.0;
  double f_hi_hz = 800.0;
  double peak_v = 2.0;           // peak of the designed period, volts at the amplifier output
  int crest_iterations = 30;     // 0: plain Schroeder phases

  bool IsValid(std::string* why) const;
};

struct Excitation {
  double sample_rate_hz = 0.0;
  double line_spacing_hz = 0.0;
  std::size_t period_samples = 0;
  std::vector<double> period_v;    // one period, volts
  std::vector<std::size_t> lines;  // excited DFT bins of one period, increasing
  double crest_factor = 0.0;       // peak / rms of one period

  // The period repeated `periods` times (what the amplifier plays).
  std::vector<double> Repeat(std::size_t periods) const;
  std::vector<double> LineFrequenciesHz() const;
};

// Throws std::invalid_argument with the reason when !options.IsValid().
Excitation DesignMultisine(const MultisineOptions& options);

// Largest line spacing that keeps at least `lines_per_band` lines inside the half-power band
// f0/q of the narrowest expected resonance, rounded down to a divisor of sample_rate_hz.
double LineSpacingForResonance(double f0_hz, double q, double sample_rate_hz,
                               double lines_per_band = 3.0);

}  // namespace eol::analysis
