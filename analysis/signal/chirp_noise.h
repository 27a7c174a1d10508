// Broadband excitations beside the multisine (multisine.h): a periodic chirp and band-limited
// Gaussian noise. Levels are physical: the designed signal is scaled to a peak of peak_v volts.
//
// Periodic chirp: one period of N = sample_rate_hz / line_spacing_hz samples (a whole number,
// T = N / fs) sweeps the band linearly, f(t) = f_lo + (f_hi - f_lo) t / T:
//   u(t) = peak_v sin(phi(t)),   phi(t) = 2 pi (f_lo t + (f_hi - f_lo) t^2 / (2 T)),
// so its crest factor is sqrt(2) (analysis/README.md 3). Repeated, it is periodic, so its power
// sits on the DFT lines k / T only; a chirp cannot put all of it inside [f_lo, f_hi]: about 1 %
// leaks into the lines just outside (the Fresnel skirts of width ~ sqrt((f_hi - f_lo) / T)), and
// the in-band line amplitudes ripple by about +20 %/-50 % at the edges. Estimate it with the
// periodic estimator on Excitation::lines (the band lines), as a multisine.
//
// Band-limited noise: white Gaussian samples (seeded, reproducible) filtered to [f_lo, f_hi]
// by zeroing every DFT bin of the whole record outside the band. Not periodic: estimate with
// Welch (welch.h). Its crest factor grows slowly with the record length (the largest of many
// Gaussian samples): about 4.2 for 10 s and 4.5-4.7 for a minute in a 600 Hz band, so noise
// needs about 10 times the time of a multisine for the same accuracy (analysis/README.md 3).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "analysis/signal/multisine.h"

namespace eol::analysis {

struct ChirpOptions {
  double sample_rate_hz = 8000.0;
  double line_spacing_hz = 1.0;  // 1 / period
  double f_lo_hz = 200.0;
  double f_hi_hz = 800.0;
  double peak_v = 2.0;

  bool IsValid(std::string* why) const;
};

// Throws std::invalid_argument with the reason when !options.IsValid(). The result's lines
// are the band's DFT bins; crest_factor is that of the period.
Excitation DesignPeriodicChirp(const ChirpOptions& options);

struct NoiseOptions {
  double sample_rate_hz = 8000.0;
  double f_lo_hz = 200.0;
  double f_hi_hz = 800.0;
  double peak_v = 2.0;
  std::size_t samples = 80000;  // record length
  std::uint64_t seed = 1;

  bool IsValid(std::string* why) const;
};

struct NoiseSignal {
  double sample_rate_hz = 0.0;
  std::vector<double> samples_v;  // peak exactly peak_v
  double crest_factor = 0.0;      // peak / rms of the record
};

// Throws std::invalid_argument with the reason when !options.IsValid().
NoiseSignal GenerateBandLimitedNoise(const NoiseOptions& options);

}  // namespace eol::analysis
