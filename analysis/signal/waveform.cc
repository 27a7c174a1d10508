#include "analysis/signal/waveform.h"

#include <algorithm>
#include <cmath>

namespace eol::analysis {

double PeakAbs(const std::vector<double>& x) {
  double p = 0.0;
  for (double v : x) p = std::max(p, std::abs(v));
  return p;
}

double Rms(const std::vector<double>& x) {
  if (x.empty()) return 0.0;
  double s = 0.0;
  for (double v : x) s += v * v;
  return std::sqrt(s / static_cast<double>(x.size()));
}

double CrestFactor(const std::vector<double>& x) {
  const double rms = Rms(x);
  return rms > 0.0 ? PeakAbs(x) / rms : 0.0;
}

std::vector<std::size_t> BandLines(double f_lo_hz, double f_hi_hz, double line_spacing_hz) {
  std::vector<std::size_t> lines;
  if (!(line_spacing_hz > 0.0) || !(f_hi_hz >= f_lo_hz)) return lines;
  const double k_lo = std::max(1.0, std::ceil(f_lo_hz / line_spacing_hz - 1e-9));
  const double k_hi = std::floor(f_hi_hz / line_spacing_hz + 1e-9);
  for (double k = k_lo; k <= k_hi; k += 1.0) lines.push_back(static_cast<std::size_t>(k));
  return lines;
}

}  // namespace eol::analysis
