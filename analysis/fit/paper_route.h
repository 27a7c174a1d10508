// The paper's identification route (section 3.2), for comparison with the ML fit:
// an output-error rational fit (rational_fit.h) of the measured transfer with the orders of
// eq. (22)-(23), then the coefficients mapped to physical parameters with J_r given
// (eq. 24-30, analysis/model/pmsm_network.h).
//
// Electrical: Y_e = 1 / Z measured, fitted as (1 + B2 s + B3 s^2) / (A1 + A2 s + A3 s^2 + A4 s^3)
//   (eq. 23, n_0 = 1), per-line sigma_Y = sigma_Z / |Z|^2 (first order). Then (eq. 27-30)
//   R = A1, L = A4 / B3, T = sqrt((J_r/B3)(A2 - A1 B2 - A4/B3)), C_m = B3 / J_r,
//   R_m = B2 J_r / B3.
//   The six coefficients carry one constraint the model imposes, A3 = B3 A1 + B2 A4 / B3
//   (analysis/README.md 1); its violation beyond its standard error signals unmodelled dynamics and
//   is reported as constraint_z = (A3 - B3 A1 - B2 A4/B3) / sigma.
// Mechanical: H_m = beta / I (angular acceleration per current) fitted as
//   (D1 + D2 s + D3 s^2) / (1 + C2 s + C3 s^2)   (eq. 22, d_0 = 1), then (eq. 24-26)
//   T = D3 J_r / C3,  C_m = C3 / J_r,  R_m = C2 J_r / C3   (D1, D2 should be ~0).
//   The input is a mobility Frf (angular velocity per current, rad/s/A): beta / I = j w Y.
// Uncertainties: first-order propagation of the coefficient covariance through the mapping
// (central differences, relative step 1e-6); J_r is taken as exact.
#pragma once

#include <string>
#include <vector>

#include "analysis/fit/rational_fit.h"
#include "analysis/frf.h"
#include "analysis/model/pmsm_network.h"

namespace eol::analysis {

struct PaperRouteSummary {
  bool usable = false;
  std::string message;
  RationalFitSummary rational;
  PmsmParams params;  // point estimate (R, L are 0 from H_m)
  // R_ohm, L_h (electrical only), T_nm_per_a, Cm_rad_per_nm, Rm_nms_per_rad, then the
  // derived f0_hz, Q (and Rp_ohm, electrical only), each with sigma.
  std::vector<FittedParameter> estimates;
  double constraint = 0.0;  // electrical only: A3 - (B3 A1 + B2 A4 / B3)
  double constraint_sigma = 0.0;
  double constraint_z = 0.0;

  const FittedParameter* Find(const std::string& name) const;
};

// Of the options only the iteration counts are used: orders and normalisation are the route's.
// `z` is an impedance Frf (sigma optional); J_r in kg m^2 (> 0).
PaperRouteSummary FitPaperAdmittance(const Frf& z, double inertia_kg_m2,
                                     const RationalFitOptions& options = {});
// `mobility` is an Frf of quantity kMobility (rad/s per A; sigma optional).
PaperRouteSummary FitPaperMechanical(const Frf& mobility, double inertia_kg_m2,
                                     const RationalFitOptions& options = {});

}  // namespace eol::analysis
