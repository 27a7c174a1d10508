// Transfer function from a periodic excitation recorded FROM REST, with the start transient
// removed instead of discarded: the local polynomial method for periodic excitations
// (Pintelon and Schoukens, System Identification, 2nd ed., 2012, section 7.2.3; Pintelon et
// al., "Estimation of nonparametric noise and FRF models for multivariable systems", MSSP 24,
// 2010), errors-in-variables (both channels noisy). No period is dropped.
//
// Model. The record holds P >= 2 whole periods of n samples, N = P n. Its DFT (scaled by 2/N,
// so that a steady line's amplitude is that of one period, as in periodic_frf.h) at bin m is,
// for each channel (x = input, y = output),
//   Y(m) = Y0(m) + T_Y(m) + N_Y(m),
//   - Y0: the periodic steady state, non-zero only at the excited bins m = P k (k in `lines`);
//   - T_Y: the transient, the free response of the system (of both channels) from rest to the
//     steady state over the record. It is a rational function of z = e^{j 2 pi m / N} with
//     the system's poles, so it is present at EVERY bin and smooth in m, at the scale of the
//     widest of the poles' bandwidths, in record bins: (f_pole / (2 Q)) / (line_spacing / P);
//   - N_Y: the noise, circular complex Gaussian, white in m for white sample noise:
//     E|N_Y(m)|^2 = 4 s^2 / N (s^2 the per-sample variance), the same as the period average.
// The bins m != 0 (mod P) carry neither the steady state nor its harmonics: only T + N.
//
// Estimator. For each excited bin m0 = P k take the 2 w nearest bins m0 + r with r != 0
// (mod P), w = half_width on each side (shifted to one side at DC or Nyquist), and fit the
// polynomial T(m0 + r) = sum_{j=0..R} t_j (r / r_max)^j, R = degree, by least squares to each
// channel (the same real design matrix K for both: 2 w x (R + 1)). Then
//   T_hat(m0) = t_0,  X_c = X(m0) - T_hat_X(m0),  Y_c = Y(m0) - T_hat_Y(m0),
//   H = (j w)^n Y_c / X_c   (n = output_jw_power; for the impedance X = I, Y = U, H = Z).
// The polynomial's degree and width trade bias against noise:
//   - the noise of T_hat(m0) adds to that of the bin: E|dX_c|^2 = (1 + s) E|N_X|^2 with the
//     leverage s = e_0^T (K^T K)^-1 e_0 (symmetric windows: s = 1/(2w) for R = 0, 1;
//     R = 2, 3 and P = 2: s = 0.64, 0.39, 0.29, 0.23 for w = 2, 3, 4, 5). std(H) grows by
//     sqrt(1 + s): the price of using the first period;
//   - the window spans (r_max / P) line spacings on each side, and a polynomial cannot follow
//     a transient narrower than that: a mode with f0 / (2 Q) below about r_max line_spacing /
//     P leaves a residue of its transient at the lines next to it (bias in Z at the peak).
// Defaults R = 1, w = 3 (for P = 2: bins +-1, +-3, +-5, i.e. +-2.5 line spacings on each
// side), s = 1/6: std(H) x 1.08, inside the 1.1 x the short record's bound the station
// wants. Odd degrees cost nothing over the even degree below them in symmetric windows (the
// odd terms vanish at r = 0) and follow the slope in the one-sided windows at the band's
// edges. Noise-free residue of the transient after removal, from rest, 4 Hz spacing, P = 2
// (SciPy prototype; largest over the lines, in units of the line's sigma):
//     Q = 15: 0.09 (R = 1, w = 3), 0.01 (R = 2, w = 3)
//     Q = 50: 0.35 (R = 1, w = 3), 0.16 (R = 2, w = 3), 0.32 (R = 2, w = 6)
//     Q = 150: about 3 for every choice: the mode's transient (f0 / (2 Q) = 1.3 Hz) is
//              narrower than the record's 2 Hz bins and has not decayed by the record's end
//              (tau = Q / (pi f0) = 0.12 s); such a mode also has fewer than 1 line per
//              half-power band at 4 Hz spacing (analysis/README.md 3 asks for 3): the spacing, not
//              the estimator, is wrong for it.
// The winding's L / (R + R_s) transient (tens of Hz wide) is removed far below the noise by
// any of them. Measured on f0 with `eol fit-bench --frf-method transient_lpm --sim
// time_domain` (analysis/README.md).
//
// Sigma. The residuals of the polynomial fit give the channels' noise (co)variances at each
// excited line, with q = 2 w - (R + 1) complex degrees of freedom:
//   s_X^2 = |e_X|^2 / q,  s_Y^2 = |e_Y|^2 / q,  s_YX = e_Y . conj(e_X) / q
// (e = (I - K (K^T K)^-1 K^T) [window bins], unbiased when the transient is polynomial). As
// in periodic_frf.h they are pooled over the 2 h + 1 neighbouring excited lines (h =
// noise_smoothing_lines; the noise spectra of sensor noise are smooth) and then
//   var H = w^2n (1 + s) (s_Y^2 + |H0|^2 s_X^2 - 2 Re(conj(H0) s_YX)) / |X_c|^2,  H0 = Y_c / X_c,
// the periodic estimator's formula with the P-period average's noise replaced by that of the
// corrected bin. E|dH|^2 = sigma^2. Adjacent lines' windows share bins, so the pooled
// estimate has fewer degrees of freedom than q (2 h + 1): FrfSummary::noise_dof reports the
// effective (Satterthwaite) complex degrees of freedom tr(A)^2 / tr(A^2) of the pooled
// variance of the middle line, A being the quadratic form it applies to the noise (nu = 2 x
// that in real terms; measured values in tests/analysis/transient_frf_test.cc).
//
// Measured (eol fit-bench, time-domain records from rest, 200-800 Hz at 4 Hz, P = 2, 2 mV /
// 1 mA noise, 1000 runs, Q = 50): std(f0) 1.03 x the bound of the channels' true noise over
// the whole 0.5 s, bias +0.25 std (the mode's transient residue), coverage of +-2 sigma 96 %
// (the leverage term is conservative for f0: neighbouring lines' removal errors are
// correlated). Q = 15: 1.04, bias 0.02 std. Q = 150: 1.15, bias 0.6 std (see above).
//
// Cost: one real FFT of the whole record per channel (N log N), then per excited line a
// (2 w) x (R + 1) least-squares fit: O(N log N + lines w R^2). Under a millisecond for the
// recipe's record (analysis/README.md).
//
// Refusals as periodic_frf.h (CheckChannels: NaN, clipping, unequal lengths; no signal when
// more than a tenth of the lines have their corrected input within min_line_snr of the noise).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "analysis/signal/periodic_frf.h"
#include "analysis/signal/recording.h"

namespace eol::analysis {

struct TransientFrfOptions {
  std::size_t degree = 1;      // R, the local polynomial's degree (0..6)
  std::size_t half_width = 3;  // w, non-excited bins on each side; 2 w > R + 1 (residual dof)
  // Input amplitude over the corrected bin's noise below which a line has no signal.
  double min_line_snr = 10.0;
  // Half-width h of the pooling of the noise (co)variances over neighbouring lines. Wider
  // than periodic_frf.h's 5: adjacent windows share most of their bins, so 2 h + 1 = 21
  // lines give about 18 complex dof at P = 2 (11 lines: 10, and chi2/dof 1.10 from the
  // weights' scatter, nu / (nu - 2) with nu = 20 real dof; 21 lines: 1.05).
  std::size_t noise_smoothing_lines = 10;

  bool IsValid(std::string* why) const;
};

// `lines` are the excited bins of one period (Excitation::lines); the record must hold at
// least 2 whole periods (all are used). Never throws for bad data: usable == false with the
// reason. Frf::method is "transient-lpm"; periods_used = P, periods_dropped = 0.
FrfSummary EstimateTransientTransfer(const ChannelPair& pair, const std::vector<std::size_t>& lines,
                                     const TransientFrfOptions& options);

// The impedance Z = U / I of a recording: EstimateTransientTransfer(ChannelPair::Impedance(r)).
FrfSummary EstimateTransientFrf(const Recording& recording, const std::vector<std::size_t>& lines,
                                const TransientFrfOptions& options);

}  // namespace eol::analysis
