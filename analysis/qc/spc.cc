#include "analysis/qc/spc.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>

#include "analysis/text.h"

namespace eol::analysis {
namespace {

constexpr std::array<SpcConstants, 9> kTable = {{
    {2, 1.880, 1.128, 0.000, 3.267},
    {3, 1.023, 1.693, 0.000, 2.574},
    {4, 0.729, 2.059, 0.000, 2.282},
    {5, 0.577, 2.326, 0.000, 2.114},
    {6, 0.483, 2.534, 0.000, 2.004},
    {7, 0.419, 2.704, 0.076, 1.924},
    {8, 0.373, 2.847, 0.136, 1.864},
    {9, 0.337, 2.970, 0.184, 1.816},
    {10, 0.308, 3.078, 0.223, 1.777},
}};

// Messages: 4 significant digits (a control limit of 417.765 Hz reads 417.8).
std::string Num(double v) { return Significant(v, 4); }

double Mean(const std::vector<double>& v) {
  double sum = 0.0;
  for (double x : v) sum += x;
  return v.empty() ? 0.0 : sum / static_cast<double>(v.size());
}

// min(USL - mean, mean - LSL) / (3 sigma) over the limits present; (USL - LSL) / (6 sigma).
void Indices(double mean, double sigma, const Limit& l, std::optional<double>* p,
             std::optional<double>* pk) {
  if (!(sigma > 0.0)) return;
  if (l.lo && l.hi) *p = (*l.hi - *l.lo) / (6.0 * sigma);
  std::optional<double> k;
  if (l.hi) k = (*l.hi - mean) / (3.0 * sigma);
  if (l.lo) {
    const double lower = (mean - *l.lo) / (3.0 * sigma);
    k = k ? std::min(*k, lower) : lower;
  }
  *pk = k;
}

}  // namespace

std::optional<SpcConstants> SpcConstantsFor(std::size_t n) {
  for (const SpcConstants& c : kTable)
    if (c.n == n) return c;
  return std::nullopt;
}

IMrChart ComputeIMr(const std::vector<double>& x) {
  IMrChart c;
  c.values = x;
  if (x.size() < 2) {
    c.message = "an I-MR chart needs at least 2 values (have " + std::to_string(x.size()) + ")";
    return c;
  }
  for (std::size_t i = 1; i < x.size(); ++i) c.moving_ranges.push_back(std::abs(x[i] - x[i - 1]));
  c.mr_bar = Mean(c.moving_ranges);
  const SpcConstants two = *SpcConstantsFor(2);
  c.sigma_within = c.mr_bar / two.d2;
  const double mean = Mean(x);
  c.individuals = {mean, mean - kE2 * c.mr_bar, mean + kE2 * c.mr_bar};
  c.moving_range = {c.mr_bar, two.d3 * c.mr_bar, two.d4 * c.mr_bar};
  c.usable = true;
  return c;
}

XbarRChart ComputeXbarR(const std::vector<double>& x, std::size_t n) {
  XbarRChart c;
  c.subgroup_size = n;
  const std::optional<SpcConstants> k = SpcConstantsFor(n);
  if (!k) {
    c.message = "subgroup size must be 2..10 (have " + std::to_string(n) + ")";
    return c;
  }
  const std::size_t groups = x.size() / n;
  c.left_out = x.size() - groups * n;
  for (std::size_t j = 0; j < groups; ++j) {
    const auto b = x.begin() + static_cast<std::ptrdiff_t>(j * n);
    const auto e = b + static_cast<std::ptrdiff_t>(n);
    const auto [lo, hi] = std::minmax_element(b, e);
    c.means.push_back(Mean(std::vector<double>(b, e)));
    c.ranges.push_back(*hi - *lo);
  }
  if (groups < 2) {
    c.message = "an X-bar/R chart needs at least 2 complete subgroups of " + std::to_string(n) +
                " (have " + std::to_string(x.size()) + " values)";
    return c;
  }
  c.r_bar = Mean(c.ranges);
  c.sigma_within = c.r_bar / k->d2;
  const double centre = Mean(c.means);
  c.xbar = {centre, centre - k->a2 * c.r_bar, centre + k->a2 * c.r_bar};
  c.range = {c.r_bar, k->d3 * c.r_bar, k->d4 * c.r_bar};
  c.usable = true;
  if (c.left_out)
    c.message = std::to_string(c.left_out) + " newest values left out (an incomplete subgroup)";
  return c;
}

bool SpcRuleOptions::IsValid(std::string* why) const {
  if (run_length == 1) return (*why = "run_length must be 0 (off) or at least 2", false);
  if (trend_length == 1 || trend_length == 2)
    return (*why = "trend_length must be 0 (off) or at least 3", false);
  return true;
}

std::vector<SpcAlarm> ApplyRunRules(const std::vector<double>& p, const ControlLimits& l,
                                    const SpcRuleOptions& o) {
  std::vector<SpcAlarm> out;
  int side = 0;                // +1 above the centre, -1 below, 0 on it
  std::size_t side_first = 0;  // first point of the current one-sided run
  bool side_fired = false;
  int dir = 0;  // +1 rising, -1 falling, 0 neither
  std::size_t trend_first = 0;
  bool trend_fired = false;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double v = p[i];
    if (o.beyond_limits && (v > l.ucl || v < l.lcl))
      out.push_back({1, i, i, v,
                     "rule 1: a point at " + Num(v) + " beyond the " +
                         (v > l.ucl ? "UCL " + Num(l.ucl) : "LCL " + Num(l.lcl))});
    const int s = v > l.centre ? 1 : v < l.centre ? -1 : 0;
    if (s != side || s == 0) {
      side = s;
      side_first = i;
      side_fired = false;
    }
    if (o.run_length && s != 0 && !side_fired && i - side_first + 1 >= o.run_length) {
      side_fired = true;
      out.push_back({2, i, side_first, v,
                     "rule 2: " + std::to_string(o.run_length) + " points in a row " +
                         (s > 0 ? "above" : "below") + " the centre line " + Num(l.centre)});
    }
    if (i > 0) {
      const int d = p[i] > p[i - 1] ? 1 : p[i] < p[i - 1] ? -1 : 0;
      if (d != dir || d == 0) {
        dir = d;
        trend_first = i - 1;
        trend_fired = false;
      }
      if (o.trend_length && d != 0 && !trend_fired && i - trend_first + 1 >= o.trend_length) {
        trend_fired = true;
        out.push_back({3, i, trend_first, v,
                       "rule 3: " + std::to_string(o.trend_length) + " points in a row " +
                           (d > 0 ? "increasing" : "decreasing")});
      }
    }
  }
  return out;
}

CapabilityIndices ComputeCapabilityIndices(const std::vector<double>& values, const Limit& limits,
                                           std::size_t subgroup_size) {
  CapabilityIndices c;
  c.sample = Summarize(values);
  if (subgroup_size <= 1) {
    const IMrChart imr = ComputeIMr(values);
    c.sigma_within = imr.sigma_within;
    c.within_method = "MRbar/d2 (d2 = 1.128)";
  } else {
    const XbarRChart xr = ComputeXbarR(values, subgroup_size);
    c.sigma_within = xr.sigma_within;
    const auto k = SpcConstantsFor(subgroup_size);
    c.within_method = "Rbar/d2 (n = " + std::to_string(subgroup_size) +
                      (k ? ", d2 = " + Num(k->d2) : std::string()) + ")";
    if (!xr.usable) {
      c.message = xr.message;
      return c;
    }
  }
  if (c.sample.n < 2) {
    c.message = "fewer than 2 values";
    return c;
  }
  if (!(c.sample.sd > 0.0)) {
    c.message = "no spread (every value equal)";
    return c;
  }
  Indices(c.sample.mean, c.sample.sd, limits, &c.pp, &c.ppk);
  Indices(c.sample.mean, c.sigma_within, limits, &c.cp, &c.cpk);
  c.usable = c.sigma_within > 0.0;
  if (c.cpk && c.sample.n < kMinCapabilityUnits) {
    const double n = static_cast<double>(c.sample.n);
    const double half = 1.96 * std::sqrt(1.0 / (9.0 * n) + *c.cpk * *c.cpk / (2.0 * (n - 1.0)));
    c.caveat = "only " + std::to_string(c.sample.n) + " units (" +
               std::to_string(kMinCapabilityUnits) + " or more for a capability index): Cpk " +
               Num(*c.cpk) + " lies in about [" + Num(*c.cpk - half) + ", " + Num(*c.cpk + half) +
               "] (95 %)";
  }
  if (!c.usable)
    c.message = "no within-subgroup spread (" + c.within_method + " is 0): no Cp/Cpk";
  else if (!c.ppk)
    c.message = "no limits";
  return c;
}

PhasedChart ComputePhasedChart(const std::vector<double>& values,
                               const std::vector<double>& baseline, std::size_t subgroup_size) {
  PhasedChart c;
  c.subgroup_size = std::max<std::size_t>(subgroup_size, 1);
  c.baseline_units = baseline.size();
  if (c.subgroup_size == 1) {
    const IMrChart base = ComputeIMr(baseline);
    const IMrChart all = ComputeIMr(values);
    c.usable = base.usable;
    c.message = base.usable ? "" : "baseline: " + base.message;
    c.points = values;
    c.spreads = all.moving_ranges;
    c.centre = base.individuals;
    c.spread = base.moving_range;
    c.sigma_within = base.sigma_within;
    c.baseline_points = baseline.size();
  } else {
    const XbarRChart base = ComputeXbarR(baseline, c.subgroup_size);
    const XbarRChart all = ComputeXbarR(values, c.subgroup_size);
    c.usable = base.usable;
    c.message = base.usable ? "" : "baseline: " + base.message;
    c.points = all.means;
    c.spreads = all.ranges;
    c.centre = base.xbar;
    c.spread = base.range;
    c.sigma_within = base.sigma_within;
    c.baseline_points = base.means.size();
  }
  if (c.usable && c.baseline_points < kMinBaselinePoints)
    c.caveat = "control limits from only " + std::to_string(c.baseline_points) +
               (c.subgroup_size == 1 ? " baseline units" : " baseline subgroups") + " (" +
               std::to_string(kMinBaselinePoints) + " or more for settled limits)";
  return c;
}

}  // namespace eol::analysis
