// Names of the measurements the impedance analysis produces; recipes declare limits on them.
// Each name carries its unit.
#pragma once

#include <array>
#include <string_view>

namespace eol::analysis::names {

inline constexpr std::string_view kResonanceFHz = "resonance_f_hz";    // Hz: first torsional mode
inline constexpr std::string_view kResonanceQ = "resonance_q";         // 1: its quality factor
inline constexpr std::string_view kWindingROhm = "winding_r_ohm";      // ohm: phase-pair resistance
inline constexpr std::string_view kWindingLH = "winding_l_h";          // H: phase-pair inductance
inline constexpr std::string_view kMotionalRpOhm = "motional_rp_ohm";  // ohm: peak height T^2/R_m
inline constexpr std::string_view kFitChi2PerDof = "fit_chi2_per_dof";  // 1: goodness of fit

inline constexpr std::array<std::string_view, 6> kAll = {
    kResonanceFHz, kResonanceQ, kWindingROhm, kWindingLH, kMotionalRpOhm, kFitChi2PerDof};

}  // namespace eol::analysis::names
