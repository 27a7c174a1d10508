// Learning recipe limits from good ("golden") units: `eol teach`.
//
// The statement taught: with confidence `confidence`, at most 1 - coverage of good units (the
// false-reject target, default 0.3 %) fail any taught bound. That budget alpha = 1 - coverage
// is spent bound by bound (each lo or hi of a scalar limit, each side of a mask segment):
//   allocation "physics" (default): alpha_b = alpha w_b / sum(w), the weights by design, most
//     to the bounds on the side where a defect moves the measurement (the table below); each
//     bound is a one-sided normal tolerance bound, centre -/+ k_b scale with
//     k_b = ToleranceFactorOneSided(n, 1 - alpha_b, confidence) (tolerance.h);
//   allocation "even" (the method before issue 12): every bound gets the same share,
//     p_bound = 1 - 2 alpha / B, and k = ToleranceFactorTwoSided(n, p_bound, confidence).
// A union bound (Bonferroni) over the bounds: conservative when they are correlated.
//
// Sides by physics (allocation "physics"): the declared sides are taught; a side that no bond
// defect moves keeps a plausibility bound (weight 0.002: wrong motor, station fault) so that
// the recipe keeps its shape without spending the budget there.
//   measurement        defect side  weight  why
//   resonance_f_hz     lo           0.20    a softer bond (or looser clamp) only lowers the mode
//   resonance_f_ref    lo           0.20    the same, with the clamp pressure's share of the
//     _pressure_hz                          good units' spread taken out (f0_pressure.h);
//                                           declared by teach itself when every golden unit
//                                           carries its clamp pressure and ln f0 follows ln p
//                                           (t >= 3). It then takes f0's share, and f0 keeps
//                                           plausibility bounds on both sides. Known-bad units
//                                           move share to it instead of f0.
//   motional_residue   hi           0.10    T^2/J: a softer bond lets less inertia follow the
//     _ohm_per_s                            magnets (where the torque acts); it rises about
//                                           twelve times faster than f0 falls and hardly moves
//                                           with the clamp (motor_model.h). Evidence: on the
//                                           independent generator, all ten bonds at losses of
//                                           0.85-0.94, 29 of 80 rejected with it, 19 without
//                                           (independent_population_test part 4)
//   bond_index_pct     hi           0.30    f0 and residue together, weighed by the golden
//                                           units' spread (bond_index.h; taught first: its
//                                           exponent and references from the golden units).
//                                           Evidence for 0.20 / 0.10 / 0.30 against f0 0.30
//                                           and residue 0.30 without it (analysis/qc/
//                                           README.md): independent generator, 400 all-ten
//                                           rotors at losses 0.8-0.99, seeds 1 and 2: 188 and
//                                           160 rejected against 174 and 157, three soft
//                                           71 / 89 against 66 / 88, 0 of 400 good; line model
//                                           (10000 units): one soft magnet 156 escapes
//                                           against 157, weak bonds 202 against 203, good
//                                           false rejects 1 against 3
//   second_mode_chi2   hi           0.30    a soft magnet's own mode beside the rotor's: the
//     _drop                                 likelihood-ratio drop of a second fitted mode;
//                                           taught on ln(1 + x), its tail is long (line model:
//                                           one soft magnet 0 of 64 escape against 30 without)
//   fit_chi2_per_dof   hi           0.35    a soft magnet's local mode is a peak the one-mode
//                                           model cannot follow; it only raises chi2. Taught
//                                           as a gamma (below)
//   Re Z mask max      hi           0.20    (all segments together) an extra motional peak
//                                           outside the resonance band only adds Re Z
//   resonance_q        lo           0.05    a loose or lossy bond adds damping
//   anything else      lo and hi    0.02    each side (R, L, Rp: winding and contacts)
//   Re Z mask min      lo           0.005   (all segments) plausibility only
//
// The measurement's distribution (names::GoodSpreadOf, declared in measurement_names.h beside
// the measurement's unit; teach matches no names for it). Each measurement is taught on the
// scale where good units' values are about normal; every rule in this header (outliers, centre
// and scale, factors, known-bad units, the expected false-reject rate) applies on that scale,
// and the limits and marginal band are brought back to the measurement's unit (the transforms
// are increasing, so each bound keeps its share of the budget and its confidence):
//   normal (the default: f0, Q, R, L, residue, bond index): x itself;
//   log (second_mode_chi2_drop, 1): ln(1 + x), x > -1;
//   gamma (fit_chi2_per_dof, 1: chi2 / dof of the one-mode fit): a goodness-of-fit statistic,
//     a scaled chi-square where the model holds, positive and right-skewed (unit-to-unit model
//     error widens it), taken as gamma-distributed with shape and scale unknown. Its bound is the
//     normal-based gamma tolerance bound (Krishnamoorthy, Mathew and Mukherjee, Technometrics
//     50 (2008) 69-78): y = x^(1/3) is about normal (Wilson and Hilferty), the upper bound
//     (mean(y) + k s(y))^3 with k the one-sided factor of the bound's share as above, so the
//     same confidence statement. Simulated (n = 40, confidence 0.95, 2000 teachings each):
//     at share 0.00066 (the eight-pole recipe's chi2 bound) it holds in 0.944-0.959 of them for
//     shapes 1-60, where the normal bound on x holds in 0.02 (shape 1) to 0.77 (shape 60, the
//     eight-pole motor's good units: chi2/dof 1.09-1.10 +- 0.14-0.15, shapes 55-60); over shares
//     0.00066-0.05 in 0.925-0.959 (0.86-0.89 at shape 0.5). tests/analysis/teach_test.cc:
//     chi2_4 / 4 from 40 units, 0.947 of 300 teachings against 0.12 for the normal bound.
//     A negative value is refused naming the unit.
//
// Centre and scale: method "tolerance_interval": mean and standard deviation (n - 1); method
// "mad": median and 1.4826 MAD (robust to a bad unit among the golden ones) with the factor
// for n_eff = 0.37 n, the asymptotic efficiency of the MAD for normal data.
// Marginal band: marginal_scales x scale inside each limit.
//
// Expected false-reject rate of the taught recipe: per bound the normal tail beyond it (on the
// measurement's scale above), combined as 1 - prod(1 - tail_b) (bounds independent), averaged
// over the draws below; its
// interval at `confidence` from the distribution of the true centre and scale given the golden
// ones (fiducial, the same as Jeffreys' posterior for normal data): per statistic sigma =
// s sqrt(nu / chi2_nu), mu = m + sigma N(0, 1) / sqrt(n), limits held fixed (fixed seed, 4000
// draws). For one bound its upper end at `confidence` is the bound's tolerance statement.
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
// Known-bad units (TeachLimits' `known_bad`: limit masters and torn-down rejects an engineer
// confirmed defective; allocation "physics" only). The budget alone sets every bound as above;
// a known-bad unit that passes all the scalar bounds so set is an escape. The f0 lower bound
// then takes share from the defect-side scalar bounds that catch none of the known-bad units
// (each keeps its plausibility weight and 1 - known_bad_max_donation of the rest), just as much
// as makes it catch every escape it can: the
// smallest share s with centre - k(s) scale above the escapes' f0 (k the one-sided factor as
// above). The total budget, and so the false-reject statement, is unchanged; the bound that
// catches the known defects gets more of it. Escapes whose f0 lies within what the whole
// movable share reaches stay escapes and are named: no limit within the budget catches them.
// Masks are not judged for known-bad units (one they would catch counts as an escape here).
//
// Units needed: the smallest n whose factor for the bound with the largest share is at most
// (1 + width_margin) times that of a perfectly known spread (divided by 0.37 for "mad"); also
// the distribution-free Wilks count for the same share. Fewer used units than needed: not
// usable, unless allow_few_units (then the summary says so, and the taught recipe's note).
#pragma once

#include <array>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "analysis/frf.h"
#include "analysis/qc/bond_index.h"
#include "analysis/qc/curve_mask.h"
#include "analysis/qc/f0_pressure.h"
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
  std::string allocation = "physics";  // or "even" (see above)
  double confidence = 0.95;            // gamma of the tolerance bounds
  // Share of good units passing every taught bound together: 1 - the false-reject target.
  double coverage = 0.997;
  double outlier_z = 5.0;
  double width_margin = 0.3;     // for units_needed
  bool allow_few_units = false;  // teach from fewer units than needed (said in the summary)
  int mask_segments = 12;        // in all masks; 0: no mask taught
  double mask_guard_sigma = 3.0;
  double marginal_scales = 1.0;
  // Known-bad units: the share of each donor bound's weight (above plausibility) that may move
  // to the f0 lower bound. Below 1 because a bound none of the known-bad units trips may still
  // catch a defect they do not represent (chi2 and one soft magnet).
  double known_bad_max_donation = 0.5;
  // The motor's bond-defect direction the bond index is taught for (bond_index.h): the
  // recipe's bond_index.residue_to_f0 (eol teach and POST /api/teach set it from the recipe).
  double bond_residue_to_f0 = kResidueToF0;

  bool IsValid(std::string* why) const;
};

struct TaughtStatistic {
  std::string name;  // measurement name, or "<mask>[<f_lo>-<f_hi> Hz] max|min"
  double centre = 0.0;
  double scale = 0.0;
  double lo = 0.0, hi = 0.0;  // the bounds computed (only the declared sides are used)
};

// One taught bound: which statistic, which side, its share of the false-reject budget.
struct TaughtBound {
  std::string statistic;    // TaughtStatistic::name
  bool lo = true;           // lower bound (else upper)
  bool defect_side = true;  // the side a defect moves it (else a plausibility bound)
  double share = 0.0;       // alpha_b, the share of good units it may reject
  double k = 0.0;           // the tolerance factor applied
  double limit = 0.0;
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
  double p_bound = 0.0;   // "even": coverage per statistic; "physics": 1 - the largest share
  double k_factor = 0.0;  // "even": the factor applied; "physics": that of the largest share
  int units_needed = 0;   // for the stated confidence (see above)
  int units_needed_distribution_free = 0;
  bool few_units_forced = false;  // fewer than units_needed, taught under allow_few_units
  std::vector<TaughtBound> taught_bounds;
  // Expected share of good units the taught recipe rejects, and its interval at confidence.
  double expected_false_reject = 0.0;
  double false_reject_lo = 0.0, false_reject_hi = 0.0;
  // Known-bad units (see above); empty when none were given.
  int known_bad_units = 0;
  std::vector<std::string> known_bad_escapes_budget;  // passing the limits of the budget alone
  std::vector<std::string> known_bad_escapes;         // passing the taught limits
  double f0_lo_budget_hz = 0.0;                       // the f0 lower bound the budget alone sets
  double f0_lo_hz = 0.0;                              // the taught one
  double known_bad_moved_share = 0.0;         // share of the budget moved to the f0 lower bound
  std::vector<std::string> known_bad_donors;  // bounds it was taken from ("name lo|hi")
  // When bond_index_pct is declared: its definition taught from the golden units (bond_index.h),
  // to be written into the taught recipe's "bond_index" block.
  std::optional<BondIndexDefinition> bond_index;
  // The pressure-normalised resonance (f0_pressure.h): what the regression of ln f0 on ln p over
  // the golden units found; its definition, when used, goes into the taught recipe's
  // "f0_pressure" block with the limit on resonance_f_ref_pressure_hz.
  F0PressureFit f0_pressure;
};

// Never throws for bad data: usable == false with the reason (names the unit or measurement).
TeachSummary TeachLimits(const std::vector<MeasurementSpec>& declared,
                         const std::vector<GoldenUnit>& golden, const TeachOptions& options,
                         const std::vector<GoldenUnit>& known_bad = {});

}  // namespace eol::analysis
