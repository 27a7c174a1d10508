// Impedance from a periodic excitation, errors-in-variables (both channels noisy).
//
// Over P steady-state periods, with U_p(k), I_p(k) the DFT lines of period p:
//   U = mean_p U_p,  I = mean_p I_p,  Z = U / I
//   var Z ~ |Z|^2 / P * (s_U^2/|U|^2 + s_I^2/|I|^2 - 2 Re(s_UI / (U I*)))
// with s_U^2, s_I^2, s_UI the period-to-period (co)variances (NOTES.md section 3).
// The returned sigma is the standard deviation of the complex estimate: E|dZ|^2 = sigma^2.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "analysis/frf.h"
#include "analysis/signal/recording.h"

namespace eol::analysis {

struct PeriodicFrfOptions {
  std::size_t transient_periods = 1;  // always dropped at the start
  // Further leading periods are dropped while they differ from the rest by more than this
  // many times the period-to-period scatter (a transient still decaying).
  double transient_threshold = 4.0;
  std::size_t min_periods = 2;        // steady-state periods needed for a sigma
  // Each excited line's current must stand this far above the scatter (amplitude ratio);
  // otherwise the measurement has no signal (open circuit, relay off, T(phi) ~ 0 is fine:
  // that only removes the motional peak, not the current).
  double min_line_snr = 10.0;

  bool IsValid(std::string* why) const;
};

struct FrfSummary {
  bool usable = false;
  std::string message;  // why it cannot be used, or a short description
  Frf frf;              // quantity kImpedanceOhm, method "periodic-eiv"
  std::size_t periods_used = 0;
  std::size_t periods_dropped = 0;
};

// `lines` are the excited bins of one period (Excitation::lines). Never throws for bad data:
// NaN, clipping, too few periods or no signal give usable == false with the reason.
FrfSummary EstimatePeriodicFrf(const Recording& recording, const std::vector<std::size_t>& lines,
                               const PeriodicFrfOptions& options);

}  // namespace eol::analysis
