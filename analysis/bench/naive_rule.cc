#include "analysis/bench/naive_rule.h"

#include <cmath>
#include <string>
#include <vector>

namespace eol::analysis {

bool NaivePeakRule::IsValid(std::string* why) const {
  if (!(search_lo_hz > 0.0 && search_hi_hz > search_lo_hz && window_hi_hz > window_lo_hz)) {
    if (why) *why = "naive rule: the search band and the window must be positive and increasing";
    return false;
  }
  return true;
}

std::optional<double> NaivePeakHz(const Frf& z, const NaivePeakRule& rule) {
  std::vector<std::size_t> idx;
  for (std::size_t k = 0; k < z.size(); ++k)
    if (z.freq_hz[k] >= rule.search_lo_hz && z.freq_hz[k] <= rule.search_hi_hz) idx.push_back(k);
  if (idx.size() < 3) return std::nullopt;
  // Least-squares line through |Z| over the band.
  double sf = 0, sm = 0, sff = 0, sfm = 0;
  const double n = static_cast<double>(idx.size());
  for (std::size_t k : idx) {
    const double f = z.freq_hz[k], m = std::abs(z.value[k]);
    sf += f;
    sm += m;
    sff += f * f;
    sfm += f * m;
  }
  const double slope = (n * sfm - sf * sm) / (n * sff - sf * sf);
  const double offset = (sm - slope * sf) / n;
  std::size_t best = 1;
  double best_excess = -INFINITY;
  for (std::size_t i = 1; i + 1 < idx.size(); ++i) {
    const std::size_t k = idx[i];
    const double e = std::abs(z.value[k]) - (offset + slope * z.freq_hz[k]);
    if (e > best_excess) {
      best_excess = e;
      best = i;
    }
  }
  const double a = std::abs(z.value[idx[best - 1]]), b = std::abs(z.value[idx[best]]),
               c = std::abs(z.value[idx[best + 1]]);
  const double denom = a - 2.0 * b + c;
  double shift = denom < 0.0 ? 0.5 * (a - c) / denom : 0.0;
  if (!(std::abs(shift) <= 1.0)) shift = 0.0;
  const double df = z.freq_hz[idx[best + 1]] - z.freq_hz[idx[best]];
  return z.freq_hz[idx[best]] + shift * df;
}

bool NaivePass(const Frf& z, const NaivePeakRule& rule) {
  const std::optional<double> f = NaivePeakHz(z, rule);
  return f && *f >= rule.window_lo_hz && *f <= rule.window_hi_hz;
}

}  // namespace eol::analysis
