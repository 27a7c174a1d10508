// The added-inertia method (the loudspeaker added-mass method, analysis/README.md 1): Z identifies
// only R, L, Rp, f0, Q; a second measurement with a known inertia dJ added to the rotor
// moves f0 to f0' and gives the missing sixth parameter,
//   J_r = dJ / ((f0 / f0')^2 - 1),
// and through it (pmsm_network.h FromMotional, from the fit without dJ)
//   C_m = 1 / (J_r w0^2),   R_m = J_r w0 / Q,   T = sqrt(Rp R_m),   w0 = 2 pi f0,
// all in absolute units.
// Uncertainties: first-order propagation in log space of the independent inputs
// (f0, Q, Rp) of the first fit (with their covariance), f0' of the second, and dJ (its own
// sigma), with the analytic gradients, r = (f0/f0')^2:
//   d ln J_r  = -2r/(r-1) d ln f0 + 2r/(r-1) d ln f0' + d ln dJ
//   d ln C_m  = -d ln J_r - 2 d ln f0
//   d ln R_m  =  d ln J_r + d ln f0 - d ln Q
//   d ln T    = (d ln Rp + d ln R_m) / 2
// The uncertainty grows as 1/(r - 1): dJ should move f0 by several percent, not by its sigma.
// Check: R_m and T do not change with dJ, so the second fit's Rp' should equal Rp, and
// Q'/Q = sqrt((J_r + dJ)/J_r); both are reported as z-scores (|z| >> 2: the added inertia did
// not simply add to the modal inertia, e.g. it was not rigidly attached or sits on another DOF).
#pragma once

#include <string>
#include <vector>

#include "analysis/fit/resonance_fit.h"
#include "analysis/model/pmsm_network.h"

namespace eol::analysis {

struct AddedInertiaSummary {
  bool usable = false;
  std::string message;
  PmsmParams params;  // R, L from the first fit; J_r, C_m, R_m, T from the method
  // J_r_kg_m2, T_nm_per_a, Cm_rad_per_nm, Rm_nms_per_rad with sigma, natural units.
  std::vector<FittedParameter> estimates;
  double rp_consistency_z = 0.0;  // (Rp' - Rp) / sigma
  double q_consistency_z = 0.0;   // (Q' - Q sqrt((J_r + dJ)/J_r)) / sigma

  const FittedParameter* Find(const std::string& name) const;
};

// `without` and `with` are usable one-mode fits (resonance_fit.h) of the same motor without
// and with the added inertia dJ (kg m^2, > 0; sigma >= 0).
AddedInertiaSummary EstimateFromAddedInertia(const FitSummary& without, const FitSummary& with,
                                             double added_inertia_kg_m2,
                                             double added_inertia_sigma_kg_m2 = 0.0);

}  // namespace eol::analysis
