// A production line's rotors for the production benchmark and the detectability analysis:
// the ten-pole torsional chain of analysis/model/rotor_chain.h with per-part spread, the
// clamp and the winding temperature of each test, and the defect classes of issue 7.
//
// Spread (relative standard deviations of a Gaussian unless stated; defaults below):
//   per magnet: inertia, bond stiffness (adhesive thickness and cure) and bond damping;
//   per pole: bridge stiffness; hub inertia; shaft stiffness;
//   clamp: pressure ~ N(5.5, 0.3) bar clipped to the recipe window [4.5, 6.5] bar, and the
//     fixture stiffness follows a Hertzian contact, k_fixture ~ F^(1/3):
//     k = k_nominal (p / 5.5)^(1/3) x (1 + wear spread);
//   winding: R_20 and L manufacturing spread, temperature uniform in [t_lo, t_hi] deg C with
//     copper's R = R_20 (1 + 0.00393 (t - 20));
//   transmission T (rotor position and magnetisation).
// Defect classes (a soft bond is RotorChainParams::bond_poor, 1/24 of a good bond, with the
// same per-magnet spread):
//   one_soft_magnet, two_soft_magnets, half_soft (N/2), all_soft: that many magnets with a
//     poor bond, chosen at random positions;
//   weak_bonds: every bond at a fraction of the good stiffness (and damping), uniform in
//     [weak_fraction_lo, weak_fraction_hi]: a partly cured adhesive.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "analysis/model/rotor_chain.h"
#include "analysis/model/torsional_chain.h"

namespace eol::analysis {

enum class DefectClass { kGood, kOneSoftMagnet, kTwoSoftMagnets, kHalfSoft, kAllSoft, kWeakBonds };
inline constexpr std::array<DefectClass, 6> kAllDefectClasses = {
    DefectClass::kGood,     DefectClass::kOneSoftMagnet, DefectClass::kTwoSoftMagnets,
    DefectClass::kHalfSoft, DefectClass::kAllSoft,       DefectClass::kWeakBonds};
const char* ToString(DefectClass c);

struct LineSpread {
  double magnet_inertia = 0.02;
  double bond_stiffness = 0.10;
  double bond_damping = 0.15;
  double bridge_stiffness = 0.02;
  double hub_inertia = 0.01;
  double shaft_stiffness = 0.02;
  double fixture_damping = 0.10;
  double clamp_pressure_mean_bar = 5.5;
  double clamp_pressure_sd_bar = 0.3;
  double clamp_pressure_lo_bar = 4.5;
  double clamp_pressure_hi_bar = 6.5;
  double fixture_wear = 0.015;
  double r_ohm = 0.5;  // at 20 deg C
  double l_h = 2.0e-3;
  double spread_r = 0.01;
  double spread_l = 0.02;
  double temperature_lo_c = 15.0;
  double temperature_hi_c = 35.0;
  double transmission_nm_per_a = 0.05;
  double spread_transmission = 0.05;
  double weak_fraction_lo = 0.1;
  double weak_fraction_hi = 0.5;

  bool IsValid(std::string* why) const;
};

// Probability of each defect class per unit (good = 1 - the sum).
struct DefectRates {
  double one_soft_magnet = 0.03;
  double two_soft_magnets = 0.02;
  double half_soft = 0.01;
  double all_soft = 0.02;
  double weak_bonds = 0.02;

  double Total() const;
  bool IsValid(std::string* why) const;
};

struct LineUnit {
  DefectClass defect = DefectClass::kGood;
  double clamp_pressure_bar = 0.0;
  double temperature_c = 0.0;
  ClampedMotor motor;
};

// Deterministic in (seed, index). `nominal` gives the geometry (its soft_magnets and fixture
// are replaced); nominal.fixture must be set (the line clamps in a real fixture).
LineUnit DrawLineUnit(const RotorChainParams& nominal, const LineSpread& spread,
                      const DefectRates& rates, std::uint64_t seed, std::uint64_t index);
// The same with the class forced.
LineUnit DrawLineUnit(const RotorChainParams& nominal, const LineSpread& spread, DefectClass defect,
                      std::uint64_t seed, std::uint64_t index);

// Nominal rotor (no spread) with a defect: soft magnets 0..n-1 (n from the class), or every
// bond at bond_fraction of the good one for kWeakBonds. Fixture as given in `nominal`.
RotorChainParams NominalWithDefect(const RotorChainParams& nominal, DefectClass defect,
                                   double bond_fraction);

// Z = R + sL + T^2 sum_n g_n s / (s^2 + c_n s + w_n^2) over the chain's modes (torsional_chain.h,
// proportional damping): the fast form of ClampedMotor::Impedance used for many units.
std::vector<std::complex<double>> ModalImpedance(const ClampedMotor& motor,
                                                 const std::vector<double>& freq_hz);

}  // namespace eol::analysis
