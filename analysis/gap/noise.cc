#include "analysis/gap/noise.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "analysis/qc/statistics.h"

namespace eol::analysis {

std::vector<double> NeighbourMagnitude(const Frf& h, std::span<const double> rel_var,
                                       int half_width) {
  // weights[m - 1][x - 1]: the least-squares a + c x^2 through offsets +-1..+-m gives
  // a = sum w(x) (H(-x) + H(x)), w(x) = (S4 - S2 x^2) / (N S4 - S2^2), N = 2m,
  // S2 = sum x^2, S4 = sum x^4 over the 2m offsets (m = 1: the mean of the two, w = 1/2).
  const std::size_t max_m = static_cast<std::size_t>(std::max(0, half_width));
  std::vector<std::vector<double>> weights(max_m);
  for (std::size_t m = 1; m <= max_m; ++m) {
    double s2 = 0.0, s4 = 0.0;
    for (std::size_t x = 1; x <= m; ++x) {
      const double x2 = static_cast<double>(x * x);
      s2 += 2.0 * x2;
      s4 += 2.0 * x2 * x2;
    }
    const double den = 2.0 * static_cast<double>(m) * s4 - s2 * s2;
    for (std::size_t x = 1; x <= m; ++x)
      weights[m - 1].push_back(m == 1 ? 0.5 : (s4 - s2 * static_cast<double>(x * x)) / den);
  }
  const std::size_t n = h.size();
  std::vector<double> out(n);
  for (std::size_t k = 0; k < n; ++k) {
    out[k] = std::abs(h.value[k]);
    // The widest symmetric window that fits, at most half_width lines each side.
    const std::size_t m = std::min({max_m, k, n - 1 - k});
    if (m == 0) continue;
    std::complex<double> a = 0.0;
    double w2 = 0.0;  // sum of the squared weights: a's noise variance over sigma^2
    for (std::size_t x = 1; x <= m; ++x) {
      const double w = weights[m - 1][x - 1];
      a += w * (h.value[k - x] + h.value[k + x]);
      w2 += 2.0 * w * w;
    }
    // Kept only where the neighbours predict the line within its noise: E|H_k - a|^2 =
    // (1 + w2) sigma_k^2, and beyond 9 times that (probability e^-9 for noise) the curve is
    // not locally quadratic at the line (a mode or notch a few lines wide, a glitch).
    const double rel = k < rel_var.size() ? rel_var[k] : 0.0;
    if (std::norm(h.value[k] - a) > 9.0 * (1.0 + w2) * rel * std::norm(h.value[k])) continue;
    if (std::abs(a) > 0.0) out[k] = std::abs(a);
  }
  return out;
}

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
  std::vector<double> rel(n), window;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t lo = k > static_cast<std::size_t>(w) ? k - static_cast<std::size_t>(w) : 0;
    const std::size_t hi = std::min(n - 1, k + static_cast<std::size_t>(w));
    window.assign(rho.begin() + static_cast<long>(lo), rho.begin() + static_cast<long>(hi) + 1);
    const auto mid = window.begin() + static_cast<long>(window.size() / 2);
    std::nth_element(window.begin(), mid, window.end());
    rel[k] = *mid / std::numbers::ln2;
  }
  const std::vector<double> mag = NeighbourMagnitude(h, rel);
  for (std::size_t k = 0; k < n; ++k) sigma[k] = mag[k] * std::sqrt(rel[k]);
  return sigma;
}

std::vector<double> PoolLineSigma(const Frf& h, int half_width) {
  const std::size_t n = h.size();
  if (half_width <= 0 || h.sigma.size() != n) return h.sigma;
  std::vector<double> rel(n);
  for (std::size_t k = 0; k < n; ++k)
    rel[k] = h.sigma[k] * h.sigma[k] / std::max(std::norm(h.value[k]), 1e-300);
  std::vector<double> pooled(n);
  const std::size_t w = static_cast<std::size_t>(half_width);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t lo = k > w ? k - w : 0;
    const std::size_t hi = std::min(n - 1, k + w);
    double sum = 0.0;
    for (std::size_t j = lo; j <= hi; ++j) sum += rel[j];
    pooled[k] = sum / static_cast<double>(hi - lo + 1);
  }
  const std::vector<double> mag = NeighbourMagnitude(h, pooled);
  std::vector<double> out(n);
  for (std::size_t k = 0; k < n; ++k) out[k] = mag[k] * std::sqrt(pooled[k]);
  return out;
}

double Trigamma(double x) {
  // psi'(x) = psi'(x + 1) + 1 / x^2 up to x >= 10, then the asymptotic series.
  double sum = 0.0;
  while (x < 10.0) {
    sum += 1.0 / (x * x);
    x += 1.0;
  }
  const double r = 1.0 / x, r2 = r * r;
  return sum + r + 0.5 * r2 +
         r * r2 * (1.0 / 6.0 - r2 * (1.0 / 30.0 - r2 * (1.0 / 42.0 - r2 / 30.0)));
}

double EstimateSigmaDof(std::span<const double> sigma, double max_dof) {
  const std::size_t n = sigma.size();
  if (n < 20) return 0.0;
  for (double s : sigma)
    if (!(s > 0.0) || !std::isfinite(s)) return 0.0;
  std::vector<double> d2;
  d2.reserve(n - 2);
  for (std::size_t k = 1; k + 1 < n; ++k)
    d2.push_back(2.0 *
                 (std::log(sigma[k - 1]) - 2.0 * std::log(sigma[k]) + std::log(sigma[k + 1])));
  const double centre = Median(d2);
  for (double& d : d2) d = std::abs(d - centre);
  const double spread = 1.4826 * Median(d2);
  const double trigamma = spread * spread / 6.0;
  if (!(trigamma > Trigamma(0.5 * max_dof))) return 0.0;
  // Trigamma falls monotonically: bisect nu on a log scale.
  double lo = std::log(0.1), hi = std::log(max_dof);
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (Trigamma(0.5 * std::exp(mid)) > trigamma ? lo : hi) = mid;
  }
  return std::max(kMinEstimatedSigmaDof, std::exp(0.5 * (lo + hi)));
}

}  // namespace eol::analysis
