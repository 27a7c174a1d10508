// Limit masks on a curve over frequency: a band [lo(f), hi(f)] (either side may be open),
// piecewise linear between the recipe's points, checked line by line on the measured
// impedance. A mask becomes one declared measurement: the number of lines outside it,
// named "mask_<name>_lines_outside", with the upper limit max_lines_outside.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "analysis/frf.h"
#include "analysis/qc/measurement.h"

namespace eol::analysis {

struct MaskPoint {
  double f_hz = 0.0;
  std::optional<double> lo;
  std::optional<double> hi;
};

enum class MaskQuantity { kReOhm, kAbsOhm };  // Re Z or |Z|, in ohm

struct CurveMask {
  std::string name;
  MaskQuantity quantity = MaskQuantity::kReOhm;
  std::vector<MaskPoint> points;  // increasing f_hz, at least two
  int max_lines_outside = 0;
  // A line counts as outside only beyond the bound by more than guard_sigma times its
  // sigma, so measurement noise alone does not fail a motor on the mask's edge.
  double guard_sigma = 0.0;

  std::string MeasurementName() const { return "mask_" + name + "_lines_outside"; }
  MeasurementSpec Spec() const;
  bool IsValid(std::string* why) const;
};

struct MaskCheck {
  int lines_checked = 0;
  int lines_outside = 0;
  double worst_f_hz = 0.0;    // line with the largest excursion (when any is outside)
  double worst_excess = 0.0;  // how far beyond its bound, ohm
};

// Lines of z outside the mask's frequency span are not checked.
MaskCheck CheckMask(const Frf& z, const CurveMask& mask);

}  // namespace eol::analysis
