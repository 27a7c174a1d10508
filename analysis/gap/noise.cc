#include "analysis/gap/noise.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace eol::analysis {

std::vector<double> EstimateLineSigma(const Frf& h, int half_window) {
  const std::size_t n = h.size();
  std::vector<double> sigma(n, 0.0);
  if (n < 5) return sigma;
  std::vector<double> rho(n, 0.0);
  for (std::size_t k = 1; k + 1 < n; ++k) {
    const std::complex<double> d = h.value[k - 1] - 2.0 * h.value[k] + h.value[k + 1];
    const double mag2 = std::max(std::norm(h.value[k]), 1e-300);
    rho[k] = std::norm(d) / (6.0 * mag2);
  }
  rho[0] = rho[1];
  rho[n - 1] = rho[n - 2];
  const int w = std::max(1, half_window);
  std::vector<double> window;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t lo = k > static_cast<std::size_t>(w) ? k - static_cast<std::size_t>(w) : 0;
    const std::size_t hi = std::min(n - 1, k + static_cast<std::size_t>(w));
    window.assign(rho.begin() + static_cast<long>(lo), rho.begin() + static_cast<long>(hi) + 1);
    const auto mid = window.begin() + static_cast<long>(window.size() / 2);
    std::nth_element(window.begin(), mid, window.end());
    sigma[k] = std::abs(h.value[k]) * std::sqrt(*mid / std::numbers::ln2);
  }
  return sigma;
}

std::vector<double> PoolLineSigma(const Frf& h, int half_width) {
  const std::size_t n = h.size();
  if (half_width <= 0 || h.sigma.size() != n) return h.sigma;
  std::vector<double> rel(n);
  for (std::size_t k = 0; k < n; ++k)
    rel[k] = h.sigma[k] * h.sigma[k] / std::max(std::norm(h.value[k]), 1e-300);
  std::vector<double> out(n);
  const std::size_t w = static_cast<std::size_t>(half_width);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t lo = k > w ? k - w : 0;
    const std::size_t hi = std::min(n - 1, k + w);
    double sum = 0.0;
    for (std::size_t j = lo; j <= hi; ++j) sum += rel[j];
    out[k] = std::abs(h.value[k]) * std::sqrt(sum / static_cast<double>(hi - lo + 1));
  }
  return out;
}

}  // namespace eol::analysis
