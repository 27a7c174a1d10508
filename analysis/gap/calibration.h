// Calibration of the nominal network to a simulation, and the same fit on a measurement
// (the "refit" the gap report gives separately from the unmodelled effects).
//
// Impedance: the clamped-motor model Z = R + s L + Rp / (1 + Q (s/w0 + w0/s)) fitted by
// analysis::FitMotionalResonance (weighted ML, variable projection start, Levenberg-Marquardt;
// resonance_fit.h). A noise-free simulation has no sigma: the fit then uses unit weights and
// its covariance is scaled by the (tiny) residual.
// Mobility: the rigid shaft M = g / (s + a) (effects.h). 1/M = s/g + a/g is linear in
// u = 1/g and v = a/g; with d(1/M) = -dM / M^2 the weighted least squares
//   min sum_k |M_k|^4 / sigma_k^2 |s_k u + v - 1/M_k|^2      (unit weights without sigma)
// starts the weighted ML fit of M itself (fit/least_squares.h, theta = (ln g, a / scale),
// analytic Jacobian dM/d ln g = M, dM/da = -M / (s + a)); the covariance (Jr^T Jr)^-1 (scaled
// by the residual without sigma) gives the uncertainties.
//
// Misfit: rel_rms = sqrt(mean |H_sim - H_nominal|^2 / mean |H_sim|^2); a simulation the
// nominal cannot represent (a split peak of a torsional chain) shows a large value here.
#pragma once

#include <string>
#include <vector>

#include "analysis/fit/resonance_fit.h"
#include "analysis/frf.h"
#include "analysis/model/effects.h"

namespace eol::analysis {

struct CalibrationOptions {
  ResonanceFitOptions fit;     // impedance only; the default searches the data's band
  double inertia_kg_m2 = 0.0;  // J_r copied into the nominal (0: unknown)

  bool IsValid(std::string* why) const;
};

struct CalibrationSummary {
  bool usable = false;
  std::string message;
  NominalNetwork nominal;
  std::vector<FittedParameter> params;  // natural units with sigma (impedance: R_ohm, L_h,
                                        // Rp_ohm, f0_hz, Q; mobility: gain, damping)
  double misfit_rel_rms = 0.0;
  double chi2_per_dof = 0.0;  // with the data's sigma (or estimated)
  bool sigma_estimated = false;
};

// Never throws for bad data; usable == false with the reason.
CalibrationSummary CalibrateNominal(const Frf& sim, const CalibrationOptions& options);

}  // namespace eol::analysis
