// The clamped rotor of a PMSM as a torsional chain (analysis/README.md 2; the paper, section 4):
//
//   magnet_i --bond_i-- pole_i --bridge_i-- hub --shaft-- clamp --fixture-- ground
//                                                 (rigid fixture: hub --shaft-- ground)
//
// one magnet and one pole per pole of the machine (i = 0..N-1), each bond and bridge its own
// spring with damper, the hub carrying the shaft's inertia, and the clamped shaft end (the
// jaws and the shaft inside them) an inertia on the fixture spring. The electromagnetic
// torque acts on the magnets, 1/N of it on each. Poor cementation is a bond much softer than
// the others ("bond_poor").
//
// The defaults are the paper's ten-pole rotor (total inertia 1.0e-4 kg m^2 as in
// population.h), calibrated with the chain's own eigenproblem so that
//   rigid fixture, every bond good   first mode 706 Hz  (FE, paper fig. 16)
//   rigid fixture, every bond poor   first mode 529 Hz  (FE, paper fig. 17)
//   default fixture, every bond good first mode 390 Hz  (measured, paper fig. 18)
// Calibration: magnets 2.5e-6, poles 6.5e-6, hub 1.0e-5, clamp 5e-6 kg m^2; a good bond
// alone would ring at 3 kHz (k = J_magnet (2 pi 3000)^2); shaft stiffness = the ten bridges'
// total; the bridge stiffness solved for 706 Hz, the poor bond for 529 Hz, the fixture for
// 390 Hz; values rounded to four digits (tests hold the three frequencies to 0.1 %).
// Dampers: bonds, bridges and shaft c = k / (60 w706) (Q 60 on the rigid mode), the poor bond
// three times lossier per stiffness, the fixture c = k / (45 w390), giving Q ~ 54 for a good
// rotor in the default fixture.
//
// What the chain then predicts (tests/analysis/torsional_chain_test.cc):
//   default fixture, every bond poor   366 Hz  (the simple series model of population.h: 350),
//                                      and the magnets ringing against the poles at 753 Hz
//                                      (Q 20, Rp 0.23 ohm at T = 0.05 N m/A): two peaks
//   rigid fixture, one soft magnet     a split peak: 567 Hz (Q ~ 29) and 724 Hz (Q ~ 52) of
//                                      comparable height, a local mode of the soft magnet
//                                      hybridised with the rotor mode
//   default fixture, one soft magnet   387 Hz, plus a local mode near 588 Hz carrying ~1/40
//                                      of the peak (Rp): the fixture hides one soft magnet
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "analysis/model/torsional_chain.h"

namespace eol::analysis {

struct SpringDamper {
  double stiffness_nm_per_rad = 0.0;
  double damping_nms_per_rad = 0.0;
};

struct RotorChainParams {
  int magnets = 10;                         // = poles of the machine
  double magnet_inertia_kg_m2 = 2.5e-6;     // each
  double pole_inertia_kg_m2 = 6.5e-6;       // each
  double hub_inertia_kg_m2 = 1.0e-5;        // hub and shaft
  SpringDamper bond{888.3, 3.338e-3};       // magnet to pole, good cementation
  SpringDamper bond_poor{36.83, 4.151e-4};  // magnet to pole, poor cementation
  SpringDamper bridge{370.1, 1.391e-3};     // pole to hub
  SpringDamper shaft{3701.0, 1.391e-2};     // hub to the clamped shaft end
  // Clamped shaft end to ground; nullopt is a rigid fixture (the shaft end is ground).
  std::optional<SpringDamper> fixture = SpringDamper{887.9, 8.052e-3};
  double clamp_inertia_kg_m2 = 5.0e-6;  // jaws and shaft end (unused when rigid)
  std::vector<int> soft_magnets;        // indices of the magnets with bond_poor

  // False with the field named in *why unless every value is finite and positive (damping
  // may be 0), magnets >= 1 and every soft magnet index is in [0, magnets) and distinct.
  bool IsValid(std::string* why) const;
};

// Inertias in order magnet_0..N-1, pole_0..N-1, hub, clamp (absent when rigid).
// Throws std::invalid_argument with the reason when !params.IsValid().
TorsionalChain BuildRotorChain(const RotorChainParams& params);

// The defects of `eol simulate --defect`, as the soft magnets of an N-magnet rotor:
//   "none" -> {},  "one_soft_magnet" -> {0},  "all_soft" -> {0..N-1},
//   "partial:<ratio>" -> the first round(ratio N) magnets, ratio in [0, 1].
// Returns false with the reason in *why for anything else.
bool SoftMagnetsForDefect(const std::string& defect, int magnets, std::vector<int>* soft,
                          std::string* why);

}  // namespace eol::analysis
