// Statistics of a measurement over many tests, for quality engineering: the sample summary,
// the drift trend and the type-1 gauge study. Pure computation: values in, summaries out; the
// station reads the values from the store (station/reports/stats_report.h).
//
// Conventions (every figure uses the sample standard deviation s, divisor n - 1):
//
// Capability (Cp/Cpk from the within-subgroup sigma, Pp/Ppk from s) and the control charts
// are in analysis/qc/spc.h.
//
// Drift: least-squares line through the values in test order (x = 0, 1, ..., n - 1):
//   slope b = Sxy / Sxx, residual variance s_r^2 = SSE / (n - 2), sigma_b = s_r / sqrt(Sxx),
//   t = b / sigma_b, change over the window = b (n - 1).
//   The alarm fires when |t| >= alarm_t (statistically significant; 4 is a two-sided p of
//   about 1e-4 for white noise) AND |change| >= min_change_of_tolerance x (USL - LSL)
//   (large enough to matter; skipped for one-sided limits). Fixture wear, for example,
//   softens the fixture spring and lowers the resonance slowly, test after test.
//
// Type-1 gauge study (VDA 5 / Bosch booklet 10): one part, re-clamped and measured n times,
// against the tolerance T = USL - LSL:
//   Cg  = (K T) / (L s)
//   Cgk = (K T / 2 - |mean - x_ref|) / (L s / 2)
//   K = 0.2 (the gauge may use 20 % of the tolerance), L = 6 (6 sigma; 4 is the other common
//   convention, selectable); x_ref is the part's reference value (a calibrated master).
//   Capable when Cg and Cgk are both >= 1.33. Without a reference Cgk is not computed (the
//   bias is unknown). At least min_n repeats (booklet 10 asks for 50, at least 25).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "analysis/qc/measurement.h"

namespace eol::analysis {

// The median of v (the mean of the two middle values for an even count); NaN when empty.
double Median(std::vector<double> v);

struct SampleSummary {
  std::size_t n = 0;
  double mean = 0.0;
  double sd = 0.0;  // divisor n - 1; 0 for n < 2
  double min = 0.0;
  double max = 0.0;
};
SampleSummary Summarize(const std::vector<double>& values);

struct DriftOptions {
  double alarm_t = 4.0;
  double min_change_of_tolerance = 0.1;
  std::size_t min_n = 10;
  bool IsValid(std::string* why) const;
};

struct DriftSummary {
  bool usable = false;  // enough values to judge
  bool alarm = false;
  std::size_t n = 0;
  double slope_per_test = 0.0;
  double slope_sigma = 0.0;
  double t = 0.0;
  double change = 0.0;  // fitted change from the first to the last test of the window
  std::optional<double> change_of_tolerance;  // |change| / (USL - LSL)
  std::string message;
};
// `values` in test order (oldest first). `name` and `unit` only word the message.
DriftSummary DetectDrift(const std::vector<double>& values, const Limit& limits,
                         const std::string& name, const std::string& unit,
                         const DriftOptions& options = {});

struct GaugeOptions {
  double tolerance_share = 0.2;  // K
  double sigma_span = 6.0;       // L: 6 or 4
  double capable_at = 1.33;
  std::size_t min_n = 10;
  bool IsValid(std::string* why) const;
};

struct GaugeStudy {
  bool usable = false;
  std::string message;
  SampleSummary sample;
  double tolerance = 0.0;  // USL - LSL
  double cg = 0.0;
  std::optional<double> reference;
  std::optional<double> bias;  // mean - reference
  std::optional<double> cgk;
  bool repeatable = false;      // Cg >= capable_at
  std::optional<bool> capable;  // Cg and Cgk >= capable_at; unknown without a reference
};
GaugeStudy GaugeType1(const std::vector<double>& repeats, const Limit& limits,
                      std::optional<double> reference, const GaugeOptions& options = {});

}  // namespace eol::analysis
