// Welch H1 / H2 transfer estimate with coherence, for non-periodic (random) excitation.
//
// The pair (recording.h: input x, output y) is cut into K segments of M = segment_samples
// samples, each starting S = M - floor(overlap M) after the previous one (trailing samples
// that do not fill a segment are dropped), K = (N - M) / S + 1. Each segment has its mean
// removed and is multiplied by the periodic Hann window w_n = 0.5 - 0.5 cos(2 pi n / M); with
// X_s, Y_s its DFT (FFTW, fft.h RealFft) the averaged cross and auto spectra are
//   Gxx = sum_s |X_s|^2,  Gyy = sum_s |Y_s|^2,  Gxy = sum_s conj(X_s) Y_s
// (scale factors cancel in every ratio below), and on each reported bin k (f_k = k fs / M):
//   H1 = Gxy / Gxx               (unbiased by output noise; input noise biases it low)
//   H2 = Gyy / conj(Gxy)         (unbiased by input noise)
//   coherence g^2 = |Gxy|^2 / (Gxx Gyy)
// This is scipy.signal.csd / welch / coherence with window 'hann', detrend 'constant',
// noverlap = floor(overlap M): csd(x, y) = conj(X) Y, so H1 = Pxy / Pxx.
//
// Per-line sigma (E|dH|^2 = sigma^2), from the coherence (Bendat and Piersol, analysis/README.md
// 3): std|H|/|H| = sqrt(1 - g^2) / (|g| sqrt(2 n_d)), and the phase error (radians) is the same, so
// the complex error is circular with E|dH|^2 = 2 |H|^2 (1 - g^2) / (2 g^2 n_d):
//   sigma = |H| sqrt((1 - g^2) / (g^2 n_d)).
// Overlapping segments are not independent: n_d is Welch's equivalent number of averages,
//   n_d = K / (1 + 2 sum_{j=1}^{K-1} (1 - j/K) rho_j^2),   rho_j = sum_n w_n w_{n+jS} / sum_n w_n^2
// (K for no overlap, about K / 1.06 at 50 % with Hann). The formula holds for many averages
// and does not include the leakage bias of a lightly damped peak: Hann segments need
// M / fs >= 8 / B3dB for a bias of at most 2 % (analysis/README.md 3).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "analysis/frf.h"
#include "analysis/signal/recording.h"

namespace eol::analysis {

enum class WelchEstimator { kH1, kH2 };

struct WelchOptions {
  std::size_t segment_samples = 4096;  // M, at least 16
  double overlap = 0.5;                // fraction of a segment shared with the next, [0, 0.95]
  WelchEstimator estimator = WelchEstimator::kH1;
  // Reported bins: f_lo_hz <= f_k <= f_hi_hz; both 0 = every bin but DC and Nyquist.
  double f_lo_hz = 0.0;
  double f_hi_hz = 0.0;
  std::size_t min_segments = 8;  // fewer averages give no meaningful coherence
  // The median coherence g^2 over the reported bins must reach this, else the input does not
  // explain the output (no excitation, open circuit, noise dominating): not usable.
  double min_coherence = 0.5;

  bool IsValid(std::string* why) const;
};

struct WelchSummary {
  bool usable = false;
  std::string message;              // why it cannot be used, or a short description
  bool clipped = false;             // not usable because a channel clipped (clipping.h)
  Frf frf;                          // the pair's quantity, method "welch-h1" or "welch-h2"
  std::vector<double> coherence;    // g^2 on frf.freq_hz, in [0, 1]
  std::size_t segments = 0;         // K
  double effective_averages = 0.0;  // n_d
};

// Never throws for bad data: NaN, clipping, a too short record, a constant channel or a too
// low coherence give usable == false with the reason (frf then empty). Bins without input
// power (Gxx == 0) are left out of frf and coherence.
WelchSummary EstimateWelchFrf(const ChannelPair& pair, const WelchOptions& options);

}  // namespace eol::analysis
