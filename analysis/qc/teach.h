// Learning recipe limits from good ("golden") units: `eol teach`.
//
// Scalar limits. For each measurement the recipe declares (the sides it declares: lo, hi or
// both), from the n golden values:
//   method "tolerance_interval": centre = mean, scale = standard deviation (n - 1), and
//     limit = centre -/+ k scale with k = ToleranceFactorTwoSided(n, p_bound, confidence)
//     (tolerance.h): with the stated confidence, at least p_bound of good units lie inside.
//   method "mad": centre = median, scale = 1.4826 MAD (robust to a bad unit among the golden
//     ones), and k computed as above for n_eff = 0.37 n, the asymptotic efficiency of the MAD
//     against the standard deviation for normal data, so the robust limits keep the stated
//     confidence at the price of width.
// Coverage is stated for the whole recipe: a good unit must pass every bound together, so the
// tail 1 - coverage is shared equally between the B bounds taught (each lo or hi of a scalar
// limit, each lo and hi of a mask segment; Bonferroni, conservative when they are correlated):
//   p_bound = 1 - 2 (1 - coverage) / B   (the two-sided coverage used for each statistic).
// Marginal band: marginal_scales x scale inside each limit.
//
// Curve masks. The golden curves' Re Z (ohm), all on one frequency grid, is masked outside
// the band where the good units' resonance may lie: the golden f0 range widened by half of
// itself and by 5 half-power bandwidths (f0/Q, median) on each side, when the units carry
// resonance_f_hz and resonance_q (inside it the peak moves with f0, a statistic far from
// normal, and the scalar limits on f0 and Q judge it). Each side ("re_z_taught_below",
// "re_z_taught_above"; one "re_z_taught" mask without a resonance) is cut into groups of
// consecutive lines, mask_segments in all, shared in proportion to the lines. Per unit and
// group the statistics max Re Z and min Re Z are taken; each gets a tolerance bound as above
// (hi of the max, lo of the min), and the group becomes two mask points (its first and last
// line) with that flat band. The mask is judged with guard_sigma x the line's sigma
// (curve_mask.h), so measurement noise beyond the golden set's does not fail a unit. The
// per-unit maximum makes the bound a statement about units (one statistic per unit and
// group), not about lines.
// Outliers among the golden units: a unit whose robust z = |x - median| / (1.4826 MAD) exceeds
// outlier_z in any declared measurement is left out (named in the summary) before teaching.
//
// Units needed: ToleranceUnitsNeeded(p_bound, confidence, width_margin) (limits at most
// width_margin wider than with a perfectly known spread; divided by 0.37 for "mad"), and the
// distribution-free Wilks count for the same p_bound and confidence, for when normality is in
// doubt.
#pragma once

#include <array>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "analysis/frf.h"
#include "analysis/qc/curve_mask.h"
#include "analysis/qc/measurement.h"

namespace eol::analysis {

struct GoldenUnit {
  std::string label;                     // serial or file, for messages
  std::map<std::string, double> values;  // named measurements (measurement_names.h)
  Frf curve;                             // measured impedance; may be empty (then no mask)
};

// Named "tolerance_interval" and "mad" (ToString) in POST /api/teach, `eol teach --method` and
// the taught recipe's description.
enum class TeachMethod { kToleranceInterval, kMad };
inline constexpr std::array kAllTeachMethods = {TeachMethod::kToleranceInterval, TeachMethod::kMad};
const char* ToString(TeachMethod m);
// The method named `name`; std::invalid_argument "method: unknown value 'x' (accepted: ...)".
TeachMethod ParseTeachMethod(std::string_view name);
void to_json(nlohmann::json& j, const TeachMethod& m);
void from_json(const nlohmann::json& j, TeachMethod& m);

struct TeachOptions {
  TeachMethod method = TeachMethod::kToleranceInterval;
  double confidence = 0.95;  // gamma of the tolerance interval
  double coverage = 0.9973;  // share of good units passing every taught bound together
  double outlier_z = 5.0;
  double width_margin = 0.2;  // for units_needed
  int mask_segments = 12;     // in all masks; 0: no mask taught
  double mask_guard_sigma = 3.0;
  double marginal_scales = 1.0;

  bool IsValid(std::string* why) const;
};

struct TaughtStatistic {
  std::string name;  // measurement name, or "<mask>[<f_lo>-<f_hi> Hz] max|min"
  double centre = 0.0;
  double scale = 0.0;
  double lo = 0.0, hi = 0.0;  // the bounds computed (only the declared sides are used)
};

struct TeachSummary {
  bool usable = false;
  std::string message;                  // what was used, or why nothing may be used
  std::vector<MeasurementSpec> limits;  // the declared limits with learned bounds
  std::vector<CurveMask> masks;         // learned masks (empty without curves)
  std::vector<TaughtStatistic> statistics;
  std::vector<std::string> rejected;  // "label: name robust z = ..."
  int units_given = 0;
  int units_used = 0;
  int bounds = 0;         // B
  double p_bound = 0.0;   // coverage per statistic
  double k_factor = 0.0;  // the tolerance factor applied
  int units_needed = 0;   // for the stated confidence (see above)
  int units_needed_distribution_free = 0;
};

// Never throws for bad data: usable == false with the reason (names the unit or measurement).
TeachSummary TeachLimits(const std::vector<MeasurementSpec>& declared,
                         const std::vector<GoldenUnit>& golden, const TeachOptions& options);

}  // namespace eol::analysis
