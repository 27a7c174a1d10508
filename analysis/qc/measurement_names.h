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
// and nothing else (station/recipe.h refuses another).
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

}  // namespace eol::analysis::names
