// The bond index: one number that carries both signatures of a softer magnet bond, the
// resonance f0 falling and the residue A = T^2/J = Rp w0/Q rising (motor_model.h), weighted
// by how much each varies among good units.
//
//   bond_index_pct = 100 [ ln(A / A_ref) - m ln(f0 / f0_ref) ]            (percent, one-sided hi)
//
// Why: in good units the two vary for different reasons (f0 with the clamp and the bridges,
// A with the torque constant squared) and are nearly uncorrelated, while a soft bond moves
// both at once along the physics direction d = (d ln f0, d ln A) = (-1, residue_to_f0) per unit
// of softness (the ten-pole motor, all ten bonds: A rises about twelve times faster than f0
// falls, on the project's line model and on tests/peers/independent_population.py alike; the
// recipe states the ratio of its own motor, kResidueToF0 below by default). The linear
// statistic with the most separation for a shift along d among good units with covariance S
// (of ln f0, ln A) is w = S^-1 d (Fisher's discriminant); scaled so that ln A has weight 1,
// the exponent is m = -w_f0 / w_A. m = 0 is the residue alone; m grows when f0 varies little
// among good units relative to A. Evidence (analysis/qc/README.md): on the independent
// generator (m = 5.3 from 300 good units), all ten bonds at losses 0.85-0.90 were rejected
// 18 of 51 with the index against 9 of 51 with f0 and A alone at the same false-reject budget.
//
// Teaching sets m and the references from the golden units (TeachBondIndex) and writes them
// into the recipe's "bond_index" block; the station computes the index from every test's f0
// and A (AddBondIndex) before judging. Its sigma (delta method) neglects the correlation of
// the fitted f0 and A: both are far below the good units' spread.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "analysis/qc/measurement.h"
#include "analysis/qc/measurement_names.h"

namespace eol::analysis {

// d ln A / (-d ln f0) of a softer bond (all magnets): the physics direction of the defect, of
// the ten-pole motor (its chain and the independent generator). A property of the motor's
// chain, not a constant: another chain has another ratio (a heavier rotor with another
// winding: 3.5-4 near its detection limit). The recipe states it per motor
// ("bond_index": {"residue_to_f0": ...}); this value is its default.
inline constexpr double kResidueToF0 = 12.0;
inline constexpr double kMaxResidueToF0 = 1000.0;

struct BondIndexDefinition {
  double f0_exponent = 0.0;            // m, >= 0
  double f0_ref_hz = 0.0;              // geometric mean of the golden units' f0
  double residue_ref_ohm_per_s = 0.0;  // geometric mean of their residue
  // The resonance it weighs: resonance_f_hz, or resonance_f_ref_pressure_hz where the recipe
  // normalises f0 by the clamp pressure (f0_pressure.h): the clamp's share of f0's spread then
  // no longer dilutes the index (independent generator, 300 good and 60 all-ten rotors at
  // losses 0.88-0.96, seed 5, 40 golden units drawn 200 times: median z of the index 4.84 ->
  // 5.53, m 4.9 -> 7.7).
  std::string f0_name = std::string(names::kResonanceFHz);
  // The defect direction m was taught for (d ln A / -d ln f0 of the motor's softer bonds).
  double residue_to_f0 = kResidueToF0;

  bool IsValid(std::string* why) const;
  bool operator==(const BondIndexDefinition&) const = default;
};

// The index of one unit from its f0_name and motional_residue_ohm_per_s; nullopt when
// either is missing or not positive and finite.
std::optional<Estimate> BondIndex(const std::map<std::string, Estimate>& values,
                                  const BondIndexDefinition& definition);

// Adds bond_index_pct to `values` when BondIndex gives one (else leaves them unchanged: a
// declared limit on it then makes the verdict ERROR, never PASS).
void AddBondIndex(std::map<std::string, Estimate>& values, const BondIndexDefinition& definition);

// From (f0 Hz, residue ohm/s) of good units (f0 the definition's f0_name, set by the caller): m
// from their covariance of logs (m = 0 when the discriminant does not weigh A positively, e.g.
// fewer than 3 units), references their geometric means. Throws std::invalid_argument when a value
// is not positive and finite.
// `residue_to_f0` is the motor's defect direction (above), kept in the definition.
BondIndexDefinition TeachBondIndex(const std::vector<std::pair<double, double>>& f0_and_residue,
                                   double residue_to_f0 = kResidueToF0);

}  // namespace eol::analysis
