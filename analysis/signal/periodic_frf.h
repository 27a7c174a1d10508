// Transfer function from a periodic excitation, errors-in-variables (both channels noisy).
//
// For a channel pair (recording.h) with input x and output y, over P steady-state periods with
// X_p(k), Y_p(k) the DFT lines of period p:
//   X = mean_p X_p,  Y = mean_p Y_p,  H = (j w)^n Y / X      (n = output_jw_power)
//   var H = w^2n / (P |X|^2) * (s_Y^2 + |H0|^2 s_X^2 - 2 Re(conj(H0) s_YX)),   H0 = Y / X
//         = |H|^2 / P * (s_Y^2/|Y|^2 + s_X^2/|X|^2 - 2 Re(s_YX / (Y X*)))
// with s_X^2, s_Y^2, s_YX = cov(Y_p, X_p) the period-to-period (co)variances (analysis/README.md
// 3). With few periods each line's (co)variances are poor (2(P-1) degrees of freedom: 6 for the
// recipe's 4 periods), and a weighted fit with such sigmas loses efficiency (the weights'
// scatter inflates var(f0) by about (nu-2)/(nu-4) = 2 at nu = 6) and under-covers. The noise
// spectra s_X^2, s_Y^2, s_YX of sensor noise are smooth in frequency, so they are pooled
// (averaged) over the 2 h + 1 neighbouring excited lines, h = noise_smoothing_lines, before
// the line's own X, Y and H enter the formula: 2(P-1)(2h+1) degrees of freedom. Set h = 0 when
// the noise spectrum has structure at the scale of a few lines (noise shaped by the system
// itself, e.g. a load disturbance seen through a mechanical resonance).
// For the impedance x = current, y = voltage, H = Z = U / I. The returned sigma is the
// standard deviation of the complex estimate: E|dH|^2 = sigma^2.
//
// Leading periods: transient_periods are always dropped; further leading periods are dropped
// while they differ from the mean of the later ones by more than transient_threshold times
// the period-to-period scatter (a transient still decaying).
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
  std::size_t min_periods = 2;  // steady-state periods needed for a sigma
  // Each excited line's input (current) must stand this far above the scatter (amplitude
  // ratio); otherwise the measurement has no signal (open circuit, relay off). T(phi) ~ 0 is
  // fine: that only removes the motional peak, not the current.
  double min_line_snr = 10.0;
  // Half-width h of the pooling of the noise (co)variances over neighbouring lines (above).
  std::size_t noise_smoothing_lines = 5;

  bool IsValid(std::string* why) const;
};

struct FrfSummary {
  bool usable = false;
  std::string message;  // why it cannot be used, or a short description
  // Not usable because a channel reached its range (clipping.h); the judge's reason code is
  // then "clipped" (analysis/qc/measurement.h), not "analysis".
  bool clipped = false;
  Frf frf;  // the pair's quantity, method "periodic-eiv"
  std::size_t periods_used = 0;
  std::size_t periods_dropped = 0;
  // Complex degrees of freedom of the noise (co)variances behind sigma (after pooling over
  // neighbouring lines; an edge line has fewer): (P - 1)(2 h + 1) for the periodic
  // estimator, the effective value of transient_frf.h for the transient-aware one.
  double noise_dof = 0.0;
};

// `lines` are the excited bins of one period (Excitation::lines). Never throws for bad data:
// NaN, clipping, too few periods or no signal give usable == false with the reason. Lines
// whose input is too weak are dropped (and counted in the message); more than a tenth of
// them means no signal.
FrfSummary EstimatePeriodicTransfer(const ChannelPair& pair, const std::vector<std::size_t>& lines,
                                    const PeriodicFrfOptions& options);

// The impedance Z = U / I of a recording: EstimatePeriodicTransfer(ChannelPair::Impedance(r)).
FrfSummary EstimatePeriodicFrf(const Recording& recording, const std::vector<std::size_t>& lines,
                               const PeriodicFrfOptions& options);

}  // namespace eol::analysis
