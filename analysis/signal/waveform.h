// Level statistics of sampled waveforms and the DFT line grid of a band. Pure helpers shared
// by the excitation designs (multisine.h, chirp_noise.h) and the estimators.
#pragma once

#include <cstddef>
#include <vector>

namespace eol::analysis {

// max |x_t| (0 for an empty waveform).
double PeakAbs(const std::vector<double>& x);
// sqrt(mean x_t^2) (0 for an empty waveform).
double Rms(const std::vector<double>& x);
// Peak over rms, PeakAbs(x) / Rms(x): sqrt(2) for a sine, ~1.5-1.7 for a Schroeder multisine
// (analysis/README.md 3). 0 when the waveform is empty or all zero.
double CrestFactor(const std::vector<double>& x);

// The DFT bins k (f_k = k * line_spacing_hz) with f_lo_hz <= f_k <= f_hi_hz, increasing. A
// line within 1e-9 of a spacing of a band edge counts as inside. Empty when none fits.
std::vector<std::size_t> BandLines(double f_lo_hz, double f_hi_hz, double line_spacing_hz);

}  // namespace eol::analysis
