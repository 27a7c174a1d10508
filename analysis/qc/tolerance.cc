#include "analysis/qc/tolerance.h"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

namespace eol::analysis {
namespace {

double NormalPdf(double x) { return std::exp(-0.5 * x * x) / std::sqrt(2.0 * std::numbers::pi); }

// P(a, x) by its series, valid for x < a + 1.
double GammaPSeries(double a, double x) {
  double sum = 1.0 / a, term = sum, ap = a;
  for (int i = 0; i < 1000; ++i) {
    ap += 1.0;
    term *= x / ap;
    sum += term;
    if (std::abs(term) < std::abs(sum) * 1e-15) break;
  }
  return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

// Q(a, x) by Lentz's continued fraction, valid for x >= a + 1.
double GammaQFraction(double a, double x) {
  constexpr double kTiny = 1e-300;
  double b = x + 1.0 - a, c = 1.0 / kTiny, d = 1.0 / b, h = d;
  for (int i = 1; i < 1000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double del = d * c;
    h *= del;
    if (std::abs(del - 1.0) < 1e-15) break;
  }
  return std::exp(-x + a * std::log(x) - std::lgamma(a)) * h;
}

// r with Phi(z + r) - Phi(z - r) = p, z >= 0 (Newton from the z = 0 value; the left side
// increases in r with derivative phi(z + r) + phi(z - r)).
double CoverageHalfWidth(double z, double p) {
  // Above the root: with q = Phi^-1((1 + p) / 2), Phi(2z + q) - Phi(-q) >= p.
  double r = z + NormalQuantile(0.5 * (1.0 + p));
  for (int i = 0; i < 60; ++i) {
    const double g = NormalCdf(z + r) - NormalCdf(z - r) - p;
    const double dg = NormalPdf(z + r) + NormalPdf(z - r);
    if (!(dg > 0.0)) break;
    const double step = g / dg;
    r = std::max(0.5 * r, r - step);
    if (std::abs(step) < 1e-12 * (1.0 + r)) break;
  }
  return r;
}

// gamma(k) of the header's integral, composite Simpson over z in [0, 10 / sqrt(n)]. The nodes'
// r(z) and weights do not depend on k, so they are computed once per (n, p).
class ToleranceIntegral {
 public:
  ToleranceIntegral(double n, double p) : nu_(n - 1.0) {
    const int m = 200;
    const double z_max = 10.0 / std::sqrt(n), h = z_max / m;
    for (int i = 0; i <= m; ++i) {
      const double z = i * h;
      const double simpson = (i == 0 || i == m) ? 1.0 : (i % 2 ? 4.0 : 2.0);
      const double w = 2.0 * std::sqrt(n / (2.0 * std::numbers::pi)) * simpson * h / 3.0 *
                       std::exp(-0.5 * n * z * z);
      if (w < 1e-300) continue;
      const double r = CoverageHalfWidth(z, p);
      r2_.push_back(r * r);
      weight_.push_back(w);
    }
  }
  double Confidence(double k) const {
    double sum = 0.0;
    for (std::size_t i = 0; i < r2_.size(); ++i)
      sum += weight_[i] * ChiSquareUpperTail(nu_ * r2_[i] / (k * k), nu_);
    return sum;
  }

 private:
  double nu_;
  std::vector<double> r2_, weight_;
};

void CheckProbability(double v, const char* name) {
  if (!(v > 0.0 && v < 1.0)) throw std::invalid_argument(std::string(name) + " must be in (0, 1)");
}

}  // namespace

double NormalCdf(double x) { return 0.5 * std::erfc(-x / std::numbers::sqrt2); }

double NormalQuantile(double p) {
  CheckProbability(p, "NormalQuantile: p");
  // Start from a logistic-type approximation, then Newton on the CDF in the tail that is
  // better conditioned (upper tail through erfc for p > 0.5).
  const bool upper = p > 0.5;
  const double q = upper ? 1.0 - p : p;  // in (0, 0.5]
  const double t = std::sqrt(-2.0 * std::log(q));
  double x = -(t - (2.515517 + 0.802853 * t + 0.010328 * t * t) /
                       (1.0 + 1.432788 * t + 0.189269 * t * t + 0.001308 * t * t * t));
  for (int i = 0; i < 50; ++i) {
    const double f = NormalCdf(x) - q;
    const double step = f / NormalPdf(x);
    x -= step;
    if (std::abs(step) < 1e-14 * (1.0 + std::abs(x))) break;
  }
  return upper ? -x : x;
}

double GammaQ(double a, double x) {
  if (!(a > 0.0) || !(x >= 0.0)) throw std::invalid_argument("GammaQ: needs a > 0 and x >= 0");
  if (x == 0.0) return 1.0;
  if (x < a + 1.0) return 1.0 - GammaPSeries(a, x);
  return GammaQFraction(a, x);
}

double ChiSquareUpperTail(double x, double nu) { return GammaQ(0.5 * nu, 0.5 * x); }

double ToleranceFactorTwoSided(double n, double coverage, double confidence) {
  if (!(n >= 2.0)) throw std::invalid_argument("ToleranceFactorTwoSided: n must be >= 2");
  CheckProbability(coverage, "ToleranceFactorTwoSided: coverage");
  CheckProbability(confidence, "ToleranceFactorTwoSided: confidence");
  const ToleranceIntegral integral(n, coverage);
  double lo = NormalQuantile(0.5 * (1.0 + coverage)) * 0.5, hi = lo * 4.0;
  while (integral.Confidence(hi) < confidence) hi *= 2.0;
  for (int i = 0; i < 60 && hi - lo > 1e-7 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (integral.Confidence(mid) < confidence ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

double ToleranceFactorOneSided(double n, double coverage, double confidence) {
  if (!(n >= 2.0)) throw std::invalid_argument("ToleranceFactorOneSided: n must be >= 2");
  CheckProbability(coverage, "ToleranceFactorOneSided: coverage");
  CheckProbability(confidence, "ToleranceFactorOneSided: confidence");
  const double zp = NormalQuantile(coverage), nu = n - 1.0, sn = std::sqrt(n);
  // Nodes over x (the standardised sample mean) where z_p + x / sqrt(n) > 0, Simpson.
  const double x_lo = std::max(-10.0, -zp * sn), x_hi = 10.0;
  const int m = 400;
  const double h = (x_hi - x_lo) / m;
  std::vector<double> d2, w;
  for (int i = 0; i <= m; ++i) {
    const double x = x_lo + i * h;
    const double simpson = (i == 0 || i == m) ? 1.0 : (i % 2 ? 4.0 : 2.0);
    const double d = zp + x / sn;
    d2.push_back(d * d);
    w.push_back(simpson * h / 3.0 * NormalPdf(x));
  }
  const double below = NormalCdf(x_lo);  // z_p + x / sqrt(n) <= 0: the bound always holds
  auto conf = [&](double k) {
    double sum = below;
    for (std::size_t i = 0; i < d2.size(); ++i)
      sum += w[i] * ChiSquareUpperTail(nu * d2[i] / (k * k), nu);
    return sum;
  };
  double lo = std::max(1e-3, zp * 0.5), hi = std::max(1.0, zp * 2.0);
  while (conf(hi) < confidence) hi *= 2.0;
  for (int i = 0; i < 60 && hi - lo > 1e-7 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (conf(mid) < confidence ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

int OneSidedUnitsNeeded(double coverage, double confidence, double width_margin) {
  if (!(width_margin > 0.0))
    throw std::invalid_argument("OneSidedUnitsNeeded: width_margin must be positive");
  const double target = (1.0 + width_margin) * NormalQuantile(coverage);
  auto ok = [&](int n) { return ToleranceFactorOneSided(n, coverage, confidence) <= target; };
  int hi = 2;
  while (!ok(hi)) {
    if (hi > 1000000) return hi;
    hi *= 2;
  }
  if (hi == 2) return 2;
  int lo = hi / 2;
  while (hi - lo > 1) {
    const int mid = (lo + hi) / 2;
    (ok(mid) ? hi : lo) = mid;
  }
  return hi;
}

int ToleranceUnitsNeeded(double coverage, double confidence, double width_margin) {
  if (!(width_margin > 0.0))
    throw std::invalid_argument("ToleranceUnitsNeeded: width_margin must be positive");
  const double target = (1.0 + width_margin) * NormalQuantile(0.5 * (1.0 + coverage));
  auto ok = [&](int n) { return ToleranceFactorTwoSided(n, coverage, confidence) <= target; };
  int hi = 2;
  while (!ok(hi)) {
    if (hi > 1000000) return hi;
    hi *= 2;
  }
  int lo = hi / 2;  // !ok(lo) unless hi == 2
  if (hi == 2) return 2;
  while (hi - lo > 1) {
    const int mid = (lo + hi) / 2;
    (ok(mid) ? hi : lo) = mid;
  }
  return hi;
}

int WilksUnitsNeeded(double coverage, double confidence) {
  CheckProbability(coverage, "WilksUnitsNeeded: coverage");
  CheckProbability(confidence, "WilksUnitsNeeded: confidence");
  for (int n = 2; n < 100000000; ++n) {
    const double p = coverage;
    const double conf = 1.0 - n * std::pow(p, n - 1) + (n - 1) * std::pow(p, n);
    if (conf >= confidence) return n;
  }
  return 100000000;
}

}  // namespace eol::analysis
