#include "analysis/qc/statistics.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace eol::analysis {

double Median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}
namespace {

std::string Num(double v, int digits = 4) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

}  // namespace

SampleSummary Summarize(const std::vector<double>& x) {
  SampleSummary s;
  s.n = x.size();
  if (x.empty()) return s;
  double sum = 0.0;
  for (double v : x) sum += v;
  s.mean = sum / static_cast<double>(x.size());
  double ss = 0.0;
  for (double v : x) ss += (v - s.mean) * (v - s.mean);
  s.sd = x.size() > 1 ? std::sqrt(ss / static_cast<double>(x.size() - 1)) : 0.0;
  const auto [lo, hi] = std::minmax_element(x.begin(), x.end());
  s.min = *lo;
  s.max = *hi;
  return s;
}

bool DriftOptions::IsValid(std::string* why) const {
  if (!(alarm_t > 0.0)) return (*why = "alarm_t must be positive", false);
  if (!(min_change_of_tolerance >= 0.0))
    return (*why = "min_change_of_tolerance must not be negative", false);
  if (min_n < 3) return (*why = "min_n must be at least 3 (a line and its residual)", false);
  return true;
}

DriftSummary DetectDrift(const std::vector<double>& y, const Limit& limits, const std::string& name,
                         const std::string& unit, const DriftOptions& o) {
  DriftSummary d;
  d.n = y.size();
  std::string why;
  if (!o.IsValid(&why)) {
    d.message = "drift options: " + why;
    return d;
  }
  if (y.size() < o.min_n) {
    d.message = "too few tests for a trend (" + std::to_string(y.size()) + " < " +
                std::to_string(o.min_n) + ")";
    return d;
  }
  const double n = static_cast<double>(y.size());
  const double x_mean = (n - 1.0) / 2.0;
  double y_mean = 0.0;
  for (double v : y) y_mean += v;
  y_mean /= n;
  double sxx = 0.0, sxy = 0.0;
  for (std::size_t i = 0; i < y.size(); ++i) {
    const double dx = static_cast<double>(i) - x_mean;
    sxx += dx * dx;
    sxy += dx * (y[i] - y_mean);
  }
  d.slope_per_test = sxy / sxx;
  double sse = 0.0;
  for (std::size_t i = 0; i < y.size(); ++i) {
    const double r = y[i] - (y_mean + d.slope_per_test * (static_cast<double>(i) - x_mean));
    sse += r * r;
  }
  d.slope_sigma = std::sqrt(sse / (n - 2.0) / sxx);
  d.change = d.slope_per_test * (n - 1.0);
  d.usable = true;
  if (!(d.slope_sigma > 0.0)) {
    // A perfect line: any non-zero slope is certain.
    d.t = d.slope_per_test == 0.0 ? 0.0 : std::copysign(INFINITY, d.slope_per_test);
  } else {
    d.t = d.slope_per_test / d.slope_sigma;
  }
  bool large_enough = true;
  if (limits.lo && limits.hi) {
    d.change_of_tolerance = std::abs(d.change) / (*limits.hi - *limits.lo);
    large_enough = *d.change_of_tolerance >= o.min_change_of_tolerance;
  }
  const bool significant = std::abs(d.t) >= o.alarm_t;
  d.alarm = significant && large_enough;
  const std::string direction = d.slope_per_test < 0 ? "falls" : "rises";
  std::string text = name + " " + direction + " " + Num(std::abs(d.slope_per_test), 3) + " " +
                     unit + " per test (t = " + Num(d.t, 3) + ", " + std::to_string(d.n) +
                     " tests): " + Num(d.change, 3) + " " + unit + " over the window";
  if (d.change_of_tolerance)
    text += " = " + Num(100.0 * *d.change_of_tolerance, 3) + " % of the tolerance";
  if (d.alarm)
    d.message = "drift alarm: " + text +
                "; check the fixture and the station (wear, clamp, "
                "calibration) before the process leaves its limits";
  else if (significant)
    d.message = "no alarm: " + text + " (significant, but below " +
                Num(100.0 * o.min_change_of_tolerance, 3) + " % of the tolerance)";
  else
    d.message = "no alarm: " + text + " (|t| below " + Num(o.alarm_t, 3) + ")";
  return d;
}

bool GaugeOptions::IsValid(std::string* why) const {
  if (!(tolerance_share > 0.0 && tolerance_share <= 1.0))
    return (*why = "tolerance_share must be in (0, 1]", false);
  if (sigma_span != 4.0 && sigma_span != 6.0) return (*why = "sigma_span must be 4 or 6", false);
  if (!(capable_at > 0.0)) return (*why = "capable_at must be positive", false);
  if (min_n < 2) return (*why = "min_n must be at least 2", false);
  return true;
}

GaugeStudy GaugeType1(const std::vector<double>& repeats, const Limit& limits,
                      std::optional<double> reference, const GaugeOptions& o) {
  GaugeStudy g;
  g.sample = Summarize(repeats);
  g.reference = reference;
  std::string why;
  if (!o.IsValid(&why)) {
    g.message = "gauge options: " + why;
    return g;
  }
  if (!limits.lo || !limits.hi) {
    g.message = "a type-1 study needs a two-sided tolerance (lo and hi)";
    return g;
  }
  g.tolerance = *limits.hi - *limits.lo;
  if (g.sample.n < o.min_n) {
    g.message = "too few repeats (" + std::to_string(g.sample.n) + " < " + std::to_string(o.min_n) +
                "; booklet 10 asks for 50, at least 25)";
    return g;
  }
  if (!(g.sample.sd > 0.0)) {
    g.message = "no spread between repeats (every value equal): the resolution is too coarse";
    return g;
  }
  const double kt = o.tolerance_share * g.tolerance;
  g.cg = kt / (o.sigma_span * g.sample.sd);
  g.repeatable = g.cg >= o.capable_at;
  if (reference) {
    g.bias = g.sample.mean - *reference;
    g.cgk = (kt / 2.0 - std::abs(*g.bias)) / (o.sigma_span / 2.0 * g.sample.sd);
    g.capable = g.repeatable && *g.cgk >= o.capable_at;
  }
  g.usable = true;
  g.message = "Cg " + Num(g.cg, 3) + (g.repeatable ? " >= " : " < ") + Num(o.capable_at, 3);
  if (g.cgk)
    g.message += ", Cgk " + Num(*g.cgk, 3) + (*g.cgk >= o.capable_at ? " >= " : " < ") +
                 Num(o.capable_at, 3) + (*g.capable ? ": capable" : ": not capable");
  else
    g.message += (g.repeatable ? ": repeatable" : ": not repeatable") +
                 std::string("; no reference value, so no Cgk (bias unknown)");
  return g;
}

}  // namespace eol::analysis
