// Feature-level gaps: the nominal refitted to a measurement, parameter by parameter against
// the simulation's calibration, each with its uncertainty (the "calibration" view of the gap,
// reported apart from the unmodelled effects).
//
// Impedance (resonance_fit.h): f0_hz, q, peak_height_ohm (Rp: the height of Re Z's peak above
// the background), r_ohm, l_h. Mobility (calibration.h): gain_rad_per_s2_per_a, damping_per_s.
//   gap = measured - simulated,  sigma = sqrt(sigma_meas^2 + sigma_sim^2),
//   significance = gap / sigma   (sigma from the fits' covariance; a noise-free simulation's
//   sigma is ~0).
// gap_after_refit: the metric g (residual.h) of the refitted nominal: how much of the gap a
// recalibration of the nominal's own parameters absorbs.
#pragma once

#include <string>
#include <vector>

#include "analysis/gap/calibration.h"
#include "analysis/gap/effect_fit.h"

namespace eol::analysis {

struct FeatureGap {
  std::string name;
  std::string unit;
  double simulated = 0.0;
  double measured = 0.0;
  double gap = 0.0;
  double sigma = 0.0;
  double significance = 0.0;
};

struct FeatureSummary {
  bool usable = false;
  std::string message;  // why the refit failed, or what it found
  std::vector<FeatureGap> features;
  CalibrationSummary refit;
  double gap_after_refit = 0.0;
};

// `options` as for the calibration (its inertia is not used).
FeatureSummary CompareFeatures(const CalibrationSummary& simulated, const GapUnit& measured,
                               Quantity quantity, const CalibrationOptions& options);

}  // namespace eol::analysis
