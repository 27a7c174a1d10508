// Statistical process control of one measurement over units in test order: control charts
// (individuals / moving range, X-bar / R), run rules that raise drift alarms, and the
// capability indices named by the sigma they use. Pure computation: values in, charts out;
// the station reads the values from the store and draws them (station/reports/stats_report.h).
//
// Every value is in the measurement's own unit (Hz for resonance_f_hz, 1 for resonance_q);
// the indices are dimensionless. Constants are the ASTM / Montgomery table for subgroups of
// size n (d2 = E[R / sigma] of n normal values; D3, D4 bound R; A2 = 3 / (d2 sqrt(n))):
//
//    n    A2     d2     D3     D4          n    A2     d2     D3     D4
//    2  1.880  1.128  0      3.267         7  0.419  2.704  0.076  1.924
//    3  1.023  1.693  0      2.574         8  0.373  2.847  0.136  1.864
//    4  0.729  2.059  0      2.282         9  0.337  2.970  0.184  1.816
//    5  0.577  2.326  0      2.114        10  0.308  3.078  0.223  1.777
//    6  0.483  2.534  0      2.004
//
// Individuals / moving range (I-MR), for one unit at a time (x_1 .. x_N):
//   MR_i = |x_i - x_(i-1)| (i = 2..N), MRbar = mean of the N - 1 moving ranges;
//   I chart:  centre = xbar, UCL/LCL = xbar +- 2.66 MRbar   (2.66 = 3 / d2(2), E2)
//   MR chart: centre = MRbar, UCL = 3.267 MRbar, LCL = 0    (D4(2), D3(2))
//   within-subgroup sigma = MRbar / 1.128.
//
// X-bar / R, subgroups of n consecutive units (a trailing incomplete subgroup is left out):
//   xbar_j = subgroup mean, R_j = subgroup max - min, xbarbar = mean of xbar_j, Rbar = mean R_j;
//   X-bar chart: centre = xbarbar, UCL/LCL = xbarbar +- A2 Rbar
//   R chart:     centre = Rbar, UCL = D4 Rbar, LCL = D3 Rbar
//   within-subgroup sigma = Rbar / d2(n).
//
// Run rules (Western Electric / Nelson), applied to the points of one chart in order; an
// alarm is raised once per run, at the point that completes it, and names its first point:
//   rule 1: a point beyond UCL or LCL (3 sigma);
//   rule 2: 9 points in a row on the same side of the centre line (a shift);
//   rule 3: 6 points in a row steadily increasing or decreasing (a trend; 5 steps one way).
//
// Capability against the limits [LSL, USL] the units were judged against:
//   Cp  = (USL - LSL) / (6 sigma_within)   Cpk = min(USL - mean, mean - LSL) / (3 sigma_within)
//   Pp  = (USL - LSL) / (6 s)              Ppk = min(USL - mean, mean - LSL) / (3 s)
//   sigma_within is MRbar / 1.128 (subgroup size 1) or Rbar / d2(n); s is the overall sample
//   standard deviation (divisor N - 1). Cp/Cpk say what the process could do without the
//   drift between units; Pp/Ppk what it did. A one-sided limit gives no Cp/Pp and a Cpk/Ppk
//   from its one side. Below 30 units the indices carry a caveat with Cpk's approximate 95 %
//   interval (Bissell): Cpk +- 1.96 sqrt(1 / (9 N) + Cpk^2 / (2 (N - 1))).
//
// Baseline and monitoring (phase I / phase II, as SPC is run): the control limits come from an
// in-control baseline (the station takes the first PASS units of the window) and every unit,
// PASS or FAIL, is charted against them, so a run of bad units cannot widen its own limits.
// Fewer than 20 baseline points (units for I-MR, subgroups for X-bar/R) is stated as a caveat.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "analysis/qc/measurement.h"
#include "analysis/qc/statistics.h"

namespace eol::analysis {

struct SpcConstants {
  std::size_t n = 0;
  double a2 = 0.0, d2 = 0.0, d3 = 0.0, d4 = 0.0;
};
// The table above; nullopt outside n = 2..10.
std::optional<SpcConstants> SpcConstantsFor(std::size_t n);

// I chart multiplier of MRbar (3 / d2(2) as tabulated).
inline constexpr double kE2 = 2.66;

struct ControlLimits {
  double centre = 0.0;
  double lcl = 0.0;
  double ucl = 0.0;
};

struct IMrChart {
  bool usable = false;  // at least 2 values
  std::string message;
  std::vector<double> values;         // the individuals, in order
  std::vector<double> moving_ranges;  // size N - 1: moving_ranges[i - 1] = |x_i - x_(i-1)|
  double mr_bar = 0.0;
  double sigma_within = 0.0;  // MRbar / 1.128
  ControlLimits individuals;
  ControlLimits moving_range;
};
IMrChart ComputeIMr(const std::vector<double>& values);

struct XbarRChart {
  bool usable = false;  // n in 2..10 and at least 2 complete subgroups
  std::string message;
  std::size_t subgroup_size = 5;
  std::vector<double> means;   // one per complete subgroup
  std::vector<double> ranges;  // one per complete subgroup
  std::size_t left_out = 0;    // values of the trailing incomplete subgroup
  double r_bar = 0.0;
  double sigma_within = 0.0;  // Rbar / d2(n)
  ControlLimits xbar;
  ControlLimits range;
};
// Subgroup j holds values[j n .. j n + n - 1].
XbarRChart ComputeXbarR(const std::vector<double>& values, std::size_t subgroup_size = 5);

struct SpcRuleOptions {
  bool beyond_limits = true;     // rule 1
  std::size_t run_length = 9;    // rule 2; 0 turns it off
  std::size_t trend_length = 6;  // rule 3 (points, so trend_length - 1 steps); 0 turns it off
  bool IsValid(std::string* why) const;
};

struct SpcAlarm {
  int rule = 0;           // 1, 2 or 3 as above
  std::size_t index = 0;  // the point that completed the run (0-based)
  std::size_t first = 0;  // the run's first point (== index for rule 1)
  double value = 0.0;     // the point's value
  std::string message;    // "rule 2: 9 points in a row above the centre line 12.3"
};
// Alarms in the order of their `index`. Rule 2 on a point exactly on the centre line breaks
// the run; rule 3 on two equal points breaks the trend.
std::vector<SpcAlarm> ApplyRunRules(const std::vector<double>& points, const ControlLimits& limits,
                                    const SpcRuleOptions& options = {});

struct CapabilityIndices {
  SampleSummary sample;           // the overall figures (s = sample.sd)
  double sigma_within = 0.0;      // 0 when it could not be estimated
  std::string within_method;      // "MRbar/d2 (d2 = 1.128)" or "Rbar/d2 (n = 5, d2 = 2.326)"
  std::optional<double> cp, cpk;  // from sigma_within
  std::optional<double> pp, ppk;  // from s
  bool usable = false;            // s > 0 and sigma_within > 0
  std::string message;
  std::string caveat;  // below kMinCapabilityUnits: the units and Cpk's 95 % interval
};
inline constexpr std::size_t kMinCapabilityUnits = 30;
// `subgroup_size` 1 estimates sigma_within from moving ranges, 2..10 from subgroup ranges.
CapabilityIndices ComputeCapabilityIndices(const std::vector<double>& values, const Limit& limits,
                                           std::size_t subgroup_size = 1);

// Control limits from `baseline` (the in-control units), points of `values` (every unit)
// against them: I-MR for subgroup_size 1, X-bar/R for 2..10 (subgroups of consecutive units of
// each list). Unusable (with the message) when the baseline gives no limits.
struct PhasedChart {
  bool usable = false;
  std::string message;
  std::size_t subgroup_size = 1;
  std::vector<double> points;   // the individuals, or the subgroup means, of every unit
  std::vector<double> spreads;  // moving ranges (first at unit 2) or subgroup ranges
  ControlLimits centre;         // I or X-bar limits, from the baseline
  ControlLimits spread;         // MR or R limits, from the baseline
  double sigma_within = 0.0;    // the baseline's
  std::size_t baseline_units = 0, baseline_points = 0;
  std::string caveat;  // fewer than kMinBaselinePoints baseline points
};
inline constexpr std::size_t kMinBaselinePoints = 20;
PhasedChart ComputePhasedChart(const std::vector<double>& values,
                               const std::vector<double>& baseline, std::size_t subgroup_size = 1);

}  // namespace eol::analysis
