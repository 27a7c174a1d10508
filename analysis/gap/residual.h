// The gap metric and where the normalised residual is significant (the "where").
//
// Normalised residual of line k: r_k = (H_meas(f_k) - H_model(f_k)) / sigma_k, with sigma_k
// the complex std (E|dH|^2 = sigma^2), so E|r_k|^2 = 1 when the model is right.
//   gap metric   g = sqrt(mean_k |r_k|^2)          (1 within the noise)
//   chi-square   chi2 = 2 sum_k |r_k|^2            (2K real residuals, the fit module's cost)
// A chi2 with d degrees of freedom is turned into a one-sided Gaussian-equivalent z by the
// Wilson-Hilferty transform z = ((chi2/d)^(1/3) - (1 - 2/(9d))) / sqrt(2/(9d)), accurate to
// a few hundredths for d >= 6 and monotone far into the tail (no underflowing p-values).
//
// Estimated sigma: when sigma_k^2 itself rests on nu degrees of freedom (nu sigma_hat^2 /
// sigma^2 ~ chi2(nu), independent of the residual), |r_k|^2 = (chi2(2) / 2) / (chi2(nu) / nu)
// is F(2, nu)-distributed, not chi2(2) / 2: mean m = nu / (nu - 2), variance
// v = nu^3 / ((nu - 2)^2 (nu - 4)) (nu > 4). A sum of such lines is matched in mean and
// variance by a scaled chi-square a chi2(b), a = v / (2 m), b = 2 m^2 / v per line, so every
// test below runs on (sum |r|^2 / a, sum b) with the same Wilson-Hilferty z; nu = infinity
// (exact sigma) gives a = 1/2, b = 2, the plain chi2 (for 8 periods, nu = 14: m = 1.167,
// b = 1.43). The sigma scale a residual implies is sqrt(mean |r|^2 / m).
// Bands: the most significant interval [a, b] of consecutive lines (at least min_lines) is
// the one maximising z(sum_{a..b} chi2_k, sum_{a..b} d_k); it is reported when z reaches
// z_threshold, and the search repeats left and right of it. A narrow strong gap is found
// narrow (z grows like excess / sqrt(width)), a broad one broad (z grows like sqrt(width)).
// The threshold covers the look-elsewhere effect: over 601 lines of pure noise with exact
// sigma the largest interval z has a 99th percentile of 4.5 (200-run simulation); with sigma
// estimated from 4 periods (66 degrees of freedom after pooling) the tail is heavier (5.0
// gave false bands in 3 of 75 noise-only cases of `eol gap-bench`), so 6.0 is the default.
// Peaks: a broad region can hold concentrated gaps (a resonance in the wrong place has tails
// over the whole band). Inside each region the excess density chi2/dof - 1, averaged over
// smooth_lines lines, is searched for local maxima at least peak_contrast times the region's
// median density (and above 1); each peak becomes its own band, grown while the density stays
// above 1/peak_contrast of the peak and keeps falling, reported when its own z reaches the
// threshold. The region is then reported with the z of its lines outside the peaks, when
// that still reaches the threshold (a uniform gap, e.g. a series resistance, is one region).
#pragma once

#include <string>
#include <vector>

namespace eol::analysis {

// One-sided Gaussian-equivalent z of chi2 with dof degrees of freedom (Wilson-Hilferty).
double ChiSquareZ(double chi2, double dof);

// One line's contribution to the tests above: chi2 = |r|^2 / a, dof = b, for sigma^2 with
// sigma_dof degrees of freedom (0 or infinity: exact). sigma_dof must exceed 4 otherwise.
struct NoiseLine {
  double chi2 = 0.0;
  double dof = 0.0;
};
NoiseLine NoiseTerms(double r2, double sigma_dof);
// E|r|^2 for sigma_dof (1 when exact).
double ExpectedR2(double sigma_dof);

struct BandSearchOptions {
  double z_threshold = 6.0;
  int min_lines = 3;
  int max_bands = 6;
  int smooth_lines = 5;
  double peak_contrast = 10.0;

  bool IsValid(std::string* why) const;
};

struct GapBand {
  double f_lo_hz = 0.0;
  double f_hi_hz = 0.0;
  double significance = 0.0;  // z of the band's chi2, see above
  int first = 0;              // index range [first, last] into the pooled lines
  int last = 0;
};

// Lines pooled over units: chi2_k = 2 sum over units |r|^2 at freq_hz[k], dof_k = 2 units.
// freq_hz strictly increasing; all three vectors the same length. Most significant first.
std::vector<GapBand> FindGapBands(const std::vector<double>& freq_hz,
                                  const std::vector<double>& chi2, const std::vector<double>& dof,
                                  const BandSearchOptions& options);

}  // namespace eol::analysis
