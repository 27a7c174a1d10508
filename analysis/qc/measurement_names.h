// Names of the measurements the impedance analysis produces; recipes declare limits on them.
// Each name carries its unit.
#pragma once

#include <array>
#include <string_view>
#include <utility>

namespace eol::analysis::names {

inline constexpr std::string_view kResonanceFHz = "resonance_f_hz";    // Hz: first torsional mode
inline constexpr std::string_view kResonanceQ = "resonance_q";         // 1: its quality factor
inline constexpr std::string_view kWindingROhm = "winding_r_ohm";      // ohm: phase-pair resistance
inline constexpr std::string_view kWindingLH = "winding_l_h";          // H: phase-pair inductance
inline constexpr std::string_view kMotionalRpOhm = "motional_rp_ohm";  // ohm: peak height T^2/R_m
// ohm/s: T^2 / J = Rp w0 / Q, the resonance's residue (motor_model.h): rises as bonds soften
inline constexpr std::string_view kMotionalResidueOhmPerS = "motional_residue_ohm_per_s";
inline constexpr std::string_view kFitChi2PerDof = "fit_chi2_per_dof";  // 1: goodness of fit
// %: 100 [ln(A/A_ref) - m ln(f0/f0_ref)], f0 and residue weighed by the good units' spread
// (bond_index.h); only where the recipe defines it ("bond_index" block, set by teaching)
inline constexpr std::string_view kBondIndexPct = "bond_index_pct";
// 1: chi2 of the one-mode fit minus chi2 with a second motional mode added anywhere in the
// search range (impedance_analysis.h): the likelihood-ratio test for a soft magnet's local mode
// (only where the recipe declares it)
inline constexpr std::string_view kSecondModeChi2Drop = "second_mode_chi2_drop";
// Hz: f0 (p_ref / p)^m, the resonance at the reference clamp pressure (f0_pressure.h); only
// where the recipe defines it ("f0_pressure" block, set by teaching when the slope is significant)
inline constexpr std::string_view kResonanceFRefPressureHz = "resonance_f_ref_pressure_hz";
// bar: the clamp pressure read at clamp confirmation (conditions.clamp_pressure_bar); an input
// of f0_pressure.h, not a measurement a recipe judges
inline constexpr std::string_view kClampPressureBar = "clamp_pressure_bar";

// In the export schema's column order (db/export_schema.h): append only.
inline constexpr std::array<std::string_view, 10> kAll = {kResonanceFHz,
                                                          kResonanceQ,
                                                          kWindingROhm,
                                                          kWindingLH,
                                                          kMotionalRpOhm,
                                                          kFitChi2PerDof,
                                                          kMotionalResidueOhmPerS,
                                                          kBondIndexPct,
                                                          kSecondModeChi2Drop,
                                                          kResonanceFRefPressureHz};

// The unit each measurement is produced in ("1": dimensionless), as the analysis writes it;
// "" for a name the analysis does not produce. A recipe's limit states values in this unit
// and nothing else (station/daemon/recipe.h refuses another).
constexpr std::string_view UnitOf(std::string_view name) {
  constexpr std::array<std::pair<std::string_view, std::string_view>, 11> kUnits = {{
      {kResonanceFHz, "Hz"},
      {kResonanceQ, "1"},
      {kWindingROhm, "ohm"},
      {kWindingLH, "H"},
      {kMotionalRpOhm, "ohm"},
      {kFitChi2PerDof, "1"},
      {kMotionalResidueOhmPerS, "ohm/s"},
      {kBondIndexPct, "%"},
      {kSecondModeChi2Drop, "1"},
      {kResonanceFRefPressureHz, "Hz"},
      {kClampPressureBar, "bar"},
  }};
  for (const auto& [n, unit] : kUnits)
    if (n == name) return unit;
  return "";
}

// How good units' values of a measurement are distributed: the family `eol teach` learns its
// bounds in (analysis/qc/teach.h, "The measurement's distribution"), declared here with the
// measurement's unit.
enum class GoodSpread {
  kNormal,      // about normal: a physical quantity of the motor (the default)
  kLogOnePlus,  // positive with a long right tail: ln(1 + x) about normal
  kGamma,       // positive and right-skewed, a scaled chi-square: a goodness-of-fit statistic
};

constexpr GoodSpread GoodSpreadOf(std::string_view name) {
  // fit_chi2_per_dof: chi2 / dof of the one-mode fit, a scaled chi-square where the model holds;
  // model error that varies from unit to unit keeps it positive and right-skewed.
  if (name == kFitChi2PerDof) return GoodSpread::kGamma;
  // second_mode_chi2_drop: the largest likelihood-ratio drop over a search range; its tail is
  // longer than a gamma's of the same spread (line model and independent generator: ln(1 + x)
  // about symmetric, skewness 0.0-0.3 against 1.0-1.8 of x).
  if (name == kSecondModeChi2Drop) return GoodSpread::kLogOnePlus;
  return GoodSpread::kNormal;
}

}  // namespace eol::analysis::names
