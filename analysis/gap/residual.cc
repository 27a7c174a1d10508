#include "analysis/gap/residual.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace eol::analysis {
namespace {

struct Prefix {
  std::vector<double> chi2, dof;  // sums of [0, k)
};

void Search(const std::vector<double>& f, const Prefix& p, int lo, int hi,
            const BandSearchOptions& o, std::vector<GapBand>* out) {
  if (hi - lo + 1 < o.min_lines) return;
  GapBand best;
  best.significance = -std::numeric_limits<double>::infinity();
  for (int a = lo; a <= hi; ++a) {
    for (int b = a + o.min_lines - 1; b <= hi; ++b) {
      const double c =
          p.chi2[static_cast<std::size_t>(b + 1)] - p.chi2[static_cast<std::size_t>(a)];
      const double d = p.dof[static_cast<std::size_t>(b + 1)] - p.dof[static_cast<std::size_t>(a)];
      const double z = ChiSquareZ(c, d);
      if (z > best.significance) {
        best.significance = z;
        best.first = a;
        best.last = b;
      }
    }
  }
  if (!(best.significance >= o.z_threshold)) return;
  best.f_lo_hz = f[static_cast<std::size_t>(best.first)];
  best.f_hi_hz = f[static_cast<std::size_t>(best.last)];
  out->push_back(best);
  Search(f, p, lo, best.first - 1, o, out);
  Search(f, p, best.last + 1, hi, o, out);
}

}  // namespace

double ChiSquareZ(double chi2, double dof) {
  if (!(dof > 0.0) || !(chi2 >= 0.0)) return 0.0;
  const double v = 2.0 / (9.0 * dof);
  return (std::cbrt(chi2 / dof) - (1.0 - v)) / std::sqrt(v);
}

double ExpectedR2(double sigma_dof) {
  if (!(sigma_dof > 0.0) || !std::isfinite(sigma_dof)) return 1.0;
  return sigma_dof / (sigma_dof - 2.0);
}

NoiseLine NoiseTerms(double r2, double sigma_dof) {
  if (!(sigma_dof > 0.0) || !std::isfinite(sigma_dof)) return {2.0 * r2, 2.0};
  const double nu = sigma_dof;
  const double m = nu / (nu - 2.0);
  const double v = nu * nu * nu / ((nu - 2.0) * (nu - 2.0) * (nu - 4.0));
  return {r2 * 2.0 * m / v, 2.0 * m * m / v};
}

bool BandSearchOptions::IsValid(std::string* why) const {
  if (!(std::isfinite(z_threshold) && z_threshold > 0.0)) {
    if (why) *why = "z_threshold must be positive";
    return false;
  }
  if (min_lines < 1 || max_bands < 0) {
    if (why)
      *why =
          "min_lines and smooth_lines must be at least 1, max_bands not negative and "
          "peak_contrast above 1";
    return false;
  }
  return true;
}

std::vector<GapBand> FindGapBands(const std::vector<double>& freq_hz,
                                  const std::vector<double>& chi2, const std::vector<double>& dof,
                                  const BandSearchOptions& options) {
  std::vector<GapBand> bands;
  const std::size_t n = freq_hz.size();
  if (n == 0 || chi2.size() != n || dof.size() != n) return bands;
  Prefix p;
  p.chi2.assign(n + 1, 0.0);
  p.dof.assign(n + 1, 0.0);
  for (std::size_t k = 0; k < n; ++k) {
    p.chi2[k + 1] = p.chi2[k] + chi2[k];
    p.dof[k + 1] = p.dof[k] + dof[k];
  }
  std::vector<GapBand> regions;
  Search(freq_hz, p, 0, static_cast<int>(n) - 1, options, &regions);
  // Peaks inside each region (see the header).
  const int half = options.smooth_lines / 2;
  std::vector<double> smooth(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t lo = k >= static_cast<std::size_t>(half) ? k - half : 0;
    const std::size_t hi = std::min(n - 1, k + half);
    const double c = p.chi2[hi + 1] - p.chi2[lo], d = p.dof[hi + 1] - p.dof[lo];
    smooth[k] = c / d - 1.0;
  }
  for (const GapBand& region : regions) {
    std::vector<double> x(smooth.begin() + region.first, smooth.begin() + region.last + 1);
    std::vector<double> sorted = x;
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    const double background = std::max(sorted[sorted.size() / 2], 0.0);
    std::vector<char> used(x.size(), 0);
    double rest_chi2 = p.chi2[region.last + 1] - p.chi2[region.first];
    double rest_dof = p.dof[region.last + 1] - p.dof[region.first];
    for (int peaks = 0; peaks < options.max_bands; ++peaks) {
      int best = -1;
      for (int i = 0; i < static_cast<int>(x.size()); ++i) {
        if (used[i]) continue;
        const bool local_max = (i == 0 || x[i] >= x[i - 1]) &&
                               (i + 1 == static_cast<int>(x.size()) || x[i] >= x[i + 1]);
        const bool touches =
            (i > 0 && used[i - 1]) || (i + 1 < static_cast<int>(x.size()) && used[i + 1]);
        if (local_max && !touches && (best < 0 || x[i] > x[best])) best = i;
      }
      if (best < 0 || !(x[best] >= options.peak_contrast * std::max(background, 1.0))) break;
      int a = best, b = best;
      const double edge = x[best] / options.peak_contrast;
      while (a > 0 && !used[a - 1] && x[a - 1] >= edge && x[a - 1] <= x[a]) --a;
      while (b + 1 < static_cast<int>(x.size()) && !used[b + 1] && x[b + 1] >= edge &&
             x[b + 1] <= x[b])
        ++b;
      if (b - a + 1 < options.min_lines) {
        a = std::max(0, std::min(a, best - options.min_lines / 2));
        b = std::min(static_cast<int>(x.size()) - 1, std::max(b, a + options.min_lines - 1));
      }
      const int ga = region.first + a, gb = region.first + b;
      const double c = p.chi2[gb + 1] - p.chi2[ga], d = p.dof[gb + 1] - p.dof[ga];
      const double z = ChiSquareZ(c, d);
      for (int i = a; i <= b; ++i) used[i] = 1;
      if (z < options.z_threshold) continue;
      rest_chi2 -= c;
      rest_dof -= d;
      GapBand peak;
      peak.first = ga;
      peak.last = gb;
      peak.f_lo_hz = freq_hz[static_cast<std::size_t>(ga)];
      peak.f_hi_hz = freq_hz[static_cast<std::size_t>(gb)];
      peak.significance = z;
      bands.push_back(peak);
    }
    GapBand rest = region;
    rest.significance = ChiSquareZ(rest_chi2, rest_dof);
    if (rest.significance >= options.z_threshold) bands.push_back(rest);
  }
  std::sort(bands.begin(), bands.end(),
            [](const GapBand& a, const GapBand& b) { return a.significance > b.significance; });
  if (bands.size() > static_cast<std::size_t>(options.max_bands))
    bands.resize(static_cast<std::size_t>(options.max_bands));
  return bands;
}

}  // namespace eol::analysis
