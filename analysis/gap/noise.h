// Per-line noise for the gap metric: estimated when a frequency response has no sigma, and
// pooled when each line's sigma rests on too few periods.
//
// Estimate (no sigma): the second difference d_k = H_{k-1} - 2 H_k + H_{k+1} of white
// complex noise of std sigma has E|d_k|^2 = 6 sigma^2, and it cancels any curve that is
// locally linear over three lines. The relative form rho_k = |d_k|^2 / (6 |H_k|^2) is
// median-filtered over 2 half_window + 1 lines (robust to the few lines where a sharp peak
// is not locally linear) and converted back: sigma_k^2 = |H_k|^2 median(rho) / ln 2 (the
// median of an exponential variable is ln 2 times its mean). This assumes the noise is
// proportional to |H| locally (a noise floor that is smooth relative to the response).
//
// Pooling (sigma from few periods): a variance estimated from P periods has about
// 2 (P - 1) degrees of freedom, so 1/sigma_hat^2 is biased up (by 1.5 for P = 4) and the
// normalised residual is heavy-tailed. The relative variance sigma_k^2 / |H_k|^2 is averaged
// over 2 half_width + 1 lines and converted back, which multiplies the degrees of freedom by
// the window while following |H| through a resonance.
#pragma once

#include <vector>

#include "analysis/frf.h"

namespace eol::analysis {

// sigma for every line of h (at least 5 lines, roughly uniform spacing). The two end lines
// take their neighbour's value.
std::vector<double> EstimateLineSigma(const Frf& h, int half_window = 25);

// h.sigma pooled as above (half_width 0 returns it unchanged). h must have sigma.
std::vector<double> PoolLineSigma(const Frf& h, int half_width);

}  // namespace eol::analysis
