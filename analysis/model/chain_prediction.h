// What a motor's own torsional chain predicts for its end-of-line test, so that a
// recipe for a new motor type is derived from its design data (`eol recipe-new`,
// station/daemon/recipe_design.h) instead of from the ten-pole motor's constants:
//   - the mode the test fits: of the good rotor, and of rotors with half and with all of their
//     magnets poorly bonded (the chain's bond_poor; rotor_chain.h SoftMagnetsForDefect), each
//     the chain's mode the torque excites most (largest Rp, motor_model.h);
//   - the bond index's defect direction (bond_index.h residue_to_f0): d ln A / -d ln f0 of the
//     good rotor's mode as every bond softens, A = T^2/J the mode's residue. Taken as a secant:
//     from the good rotor to the rotor whose bonds have all lost the share of their stiffness
//     that lowers f0 by kDirectionF0Drop (found by bisection), the region where the index
//     matters (f0 alone within the good units' spread, the residue already risen). On the
//     ten-pole chain this gives about 12 (the compiled default it replaces).
#pragma once

#include <string>

#include "analysis/model/motor_model.h"
#include "analysis/model/rotor_chain.h"

namespace eol::analysis {

inline constexpr double kDirectionF0Drop = 0.01;  // f0 1 % low: near the detection limit

struct ChainPrediction {
  MotionalImpedance good;            // the good rotor's fitted mode (R and L of the winding)
  MotionalImpedance half_soft;       // round(N/2) magnets on bond_poor
  MotionalImpedance all_soft;        // every magnet on bond_poor
  double residue_to_f0 = 0.0;        // the defect direction (above)
  double direction_loss = 0.0;       // the bond stiffness loss the direction was taken at (0-1)
  double total_inertia_kg_m2 = 0.0;  // magnets, poles and hub (the rotor's J)
};

// The good rotor's mode alone (ChainPrediction::good). Throws std::invalid_argument naming the
// cause: an invalid chain, or no mode the torque excites.
MotionalImpedance PredictGoodMode(double r_ohm, double l_h, double transmission_nm_per_a,
                                  const RotorChainParams& rotor);

// Throws std::invalid_argument naming the cause: an invalid chain, no mode the torque excites,
// or a softening that never lowers f0 by kDirectionF0Drop (the bonds do not carry the mode).
ChainPrediction PredictChain(double r_ohm, double l_h, double transmission_nm_per_a,
                             const RotorChainParams& rotor);

}  // namespace eol::analysis
