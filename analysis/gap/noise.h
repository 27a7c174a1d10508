// Per-line noise for the gap metric: estimated when a frequency response has no sigma, and
// pooled when each line's sigma rests on too few periods.
//
// Estimate (no sigma): the second difference d_k = H_{k-1} - 2 H_k + H_{k+1} of white
// complex noise of std sigma has E|d_k|^2 = 6 sigma^2, and it cancels any curve that is
// locally linear over three lines. The relative form rho_k = |d_k|^2 / (6 |H_k|^2) is
// median-filtered over 2 half_window + 1 lines (robust to the few lines where a sharp peak
// is not locally linear) and converted back: sigma_k^2 = |H_k|^2 median(rho) / ln 2 (the
// median of an exponential variable is ln 2 times its mean), |H_k| taken from the line's
// neighbours (NeighbourMagnitude), not from the line itself. This assumes the noise is
// proportional to |H| locally (a noise floor that is smooth relative to the response).
//
// Why the neighbours: a sigma proportional to the line's own |H_k| depends on the line's noise
// draw. A line whose noise pulled |H| low gets a small sigma and a large weight, so every fit
// leans toward a lower |H|, most where the noise is large; in the admittance form (effect_fit.h)
// toward a lower |1/H|, which an added capacitance jwC mimics at high frequency. On 70 files of
// the independent generator stripped of their sigma (seed 1, tests/peers/
// independent_gap_cases.py) the line's own |H_k| had 5 of the 59 separable cases answered
// as a pair with stray_capacitance (53 of 59 named); from the neighbours, none (57 of 59).
//
// Pooling (sigma from few periods): a variance estimated from P periods has about
// 2 (P - 1) degrees of freedom, so 1/sigma_hat^2 is biased up (by 1.5 for P = 4) and the
// normalised residual is heavy-tailed. The relative variance sigma_k^2 / |H_k|^2 is averaged
// over 2 half_width + 1 lines and converted back, which multiplies the degrees of freedom by
// the window while following |H| through a resonance (|H_k| from the neighbours, as above).
//
// Degrees of freedom of a sigma that does not say (a file with sigma but no sigma_dof column):
// a variance estimated from a few periods is sigma_k^2 chi2_nu / nu, so x_k = ln sigma_hat_k^2
// scatters about the smooth ln sigma_k^2 with variance psi'(nu / 2) (psi': trigamma), and the
// second difference x_{k-1} - 2 x_k + x_{k+1}, which cancels any curve locally linear over three
// lines, has variance 6 psi'(nu / 2). Its robust variance (1.4826 MAD)^2 over the lines gives
// nu. The scatter of the sigma itself does not depend on the residual, so an effect in the
// data does not lower the estimate. On 70 files of sigma from 8 periods (nu = 14) of the
// independent generator: median 13.5; where the noise per period is near the signal (the
// period means then carry noise too) it reads 2-9. A sigma with no scatter (a model's, a
// smoothed one) reads as exact.
#pragma once

#include <span>
#include <vector>

#include "analysis/frf.h"

namespace eol::analysis {

// |H_k| of every line from its neighbours alone: |a| of the least-squares a + c x^2 through
// the lines k +- 1 .. k +- m (x the offset in lines, m = half_width, fewer near the ends; the
// mean of the two when m = 1; |H_k| itself at the end lines). Independent of line k's noise,
// exact for a curve locally quadratic over the window; its own noise variance is sigma^2 / 2
// for m = 3 (weights (7 - x^2) / 14). Where the neighbours miss the line by more than its
// noise allows (|H_k - a|^2 above 9 times its expectation (1 + sum w^2) rel_var_k |H_k|^2,
// rel_var_k = sigma_k^2 / |H_k|^2: a mode or notch a few lines wide, a glitch), the line's own
// |H_k|: the neighbours' value would put a tiny sigma on a narrow peak.
std::vector<double> NeighbourMagnitude(const Frf& h, std::span<const double> rel_var,
                                       int half_width = 3);

// sigma for every line of h (at least 5 lines, roughly uniform spacing). The two end lines
// take their neighbour's relative value.
std::vector<double> EstimateLineSigma(const Frf& h, int half_window = 25);

// h.sigma pooled as above (half_width 0 returns it unchanged). h must have sigma.
std::vector<double> PoolLineSigma(const Frf& h, int half_width);

// nu of sigma's scatter (above), at least kMinEstimatedSigmaDof; 0 (exact) when the scatter
// is below what nu = max_dof gives, or with fewer than 20 lines or a sigma that is not
// positive and finite everywhere.
inline constexpr double kMinEstimatedSigmaDof = 5.0;
double EstimateSigmaDof(std::span<const double> sigma, double max_dof = 1000.0);

// psi'(x), the trigamma function, x > 0.
double Trigamma(double x);

}  // namespace eol::analysis
