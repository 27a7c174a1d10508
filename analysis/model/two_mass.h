// Two-mass torsional system: a motor (inertia J1, viscous friction b1 to ground, driven by
// the torque Kt i) coupled to a load (inertia J2) by a shaft or coupling (stiffness k, damping
// c). The bench of shared/data/motor-bench-multisine is one; the paper's H_m (eq. 20) is the
// one-mass case.
//   J1 s^2 Th1 + b1 s Th1 = Kt I - (c s + k)(Th1 - Th2),   J2 s^2 Th2 = (c s + k)(Th1 - Th2)
// Mobility, motor angular velocity per current (rad/s/A):
//   H(s) = s Th1 / I = Kt (J2 s^2 + c s + k) / ((J1 s + b1)(J2 s^2 + c s + k) + J2 s (c s + k))
// and with b1 = 0 the textbook form
//   H(s) = Kt (J2 s^2 + c s + k) / (s (J1 J2 s^2 + (J1 + J2)(c s + k))).
// Anti-resonance (zero, the load ringing against a motor held still) and resonance (pole):
//   w_ar = sqrt(k / J2),  zeta_ar = c / (2 sqrt(k J2));
//   w_r = sqrt(k (J1 + J2) / (J1 J2)) = w_ar sqrt(J_tot / J1),  zeta_r = zeta_ar w_r / w_ar.
// Below both, H -> Kt / (J_tot s + b1) with J_tot = J1 + J2.
//
// Scaling Kt, J1, J2, k, c, b1 by one factor leaves H unchanged, so H determines only the
// identifiable form (TwoMassResponse): g = Kt / J_tot, f_ar, f_r, zeta_ar, beta = b1 / J_tot
// (and a measurement delay tau, H e^{-s tau}, from the current loop and encoder sampling):
//   H(s) = g n(s) e^{-s tau} / ((r1 s + beta) n(s) + r2 s (2 zeta_ar w_ar s + w_ar^2)),
//   n(s) = s^2 + 2 zeta_ar w_ar s + w_ar^2,  r1 = J1 / J_tot = (f_ar / f_r)^2,  r2 = 1 - r1.
// With Kt given (datasheet), TwoMassSystem::FromResponse maps back:
//   J_tot = Kt / g, J1 = r1 J_tot, J2 = r2 J_tot, k = J2 w_ar^2, c = 2 zeta_ar w_ar J2,
//   b1 = beta J_tot.
#pragma once

#include <complex>
#include <string>
#include <vector>

#include "analysis/fit/resonance_fit.h"
#include "analysis/frf.h"

namespace eol::analysis {

// The identifiable form. Units: rad/s^2/A, Hz, Hz, 1, 1/s, s.
struct TwoMassResponse {
  double gain_rad_per_s2_per_a = 0.0;  // g = Kt / J_tot
  double f_ar_hz = 0.0;
  double f_r_hz = 0.0;  // must exceed f_ar_hz (J1 < J_tot)
  double zeta_ar = 0.0;
  double friction_per_s = 0.0;  // beta = b1 / J_tot
  double delay_s = 0.0;

  std::complex<double> At(double f_hz) const;              // rad/s/A
  Frf Evaluate(const std::vector<double>& freq_hz) const;  // kMobility, method "model"
  double ZetaR() const { return zeta_ar * f_r_hz / f_ar_hz; }
};

// Physical parameters. Units: N m/A, kg m^2, kg m^2, N m/rad, N m s/rad, N m s/rad.
struct TwoMassSystem {
  double kt_nm_per_a = 0.0;
  double j1_kg_m2 = 0.0;
  double j2_kg_m2 = 0.0;
  double k_nm_per_rad = 0.0;
  double c_nms_per_rad = 0.0;
  double b1_nms_per_rad = 0.0;

  std::complex<double> Mobility(double f_hz) const;  // the first equation above, rad/s/A
  TwoMassResponse Response() const;
  static TwoMassSystem FromResponse(const TwoMassResponse& r, double kt_nm_per_a);
};

struct TwoMassFitOptions {
  // Lines used: f_lo_hz <= f <= f_hi_hz (0, 0: all).
  double f_lo_hz = 0.0;
  double f_hi_hz = 0.0;
  bool fit_friction = false;  // add beta (analysis/README.md 5: an optional term, one parameter)
  bool fit_delay = false;     // add tau
  int max_iterations = 400;

  bool IsValid(std::string* why) const;
};

// Weighted least squares on complex data, the convention of resonance_fit.h: residual
// Re and Im of sqrt(2) (H(f_k) - H_k) / sigma_k, chi2 = |r|^2 with 2K - n_params degrees of
// freedom. Parameters ln(g, f_ar, f_r), zeta_ar and beta (linear: either may be ~0) and tau. Start:
// f_ar at the |H| minimum before the |H| maximum (f_r), g from |H| w on the lowest lines, a grid
// over zeta; finish: Levenberg-Marquardt (Eigen, MINPACK) with a central-difference Jacobian;
// covariance (Jr^T Jr)^-1 mapped to natural units. Without sigma: unit weights, noise from the
// residual, sigma_estimated set (as FitMotionalResonance). Real drives are not exactly linear: with
// sigma from the period scatter, chi2_per_dof far above 1 measures the model's (and the nonlinear
// distortion's) error, not the noise; the parameter sigmas are then scaled by sqrt(chi2_per_dof)
// (reported in `message`).
struct TwoMassFit {
  bool usable = false;
  std::string message;
  Termination termination = Termination::kInvalidInput;
  // g_rad_per_s2_per_a, f_ar_hz, f_r_hz, zeta_ar[, friction_per_s][, delay_s]
  std::vector<FittedParameter> params;
  TwoMassResponse response;
  double chi2 = 0.0;
  int dof = 0;
  double chi2_per_dof = 0.0;
  // Normalised rms model error sqrt(sum |H_model - H|^2 / sum |H|^2) over the lines used.
  double rms_relative_error = 0.0;
  bool sigma_estimated = false;

  const FittedParameter* Find(const std::string& name) const;
};

// Never throws for bad data: a non-mobility Frf, too few lines, no minimum before the maximum,
// f_r <= f_ar or zeta_ar below -2 sigma after the fit give usable == false with the reason.
TwoMassFit FitTwoMass(const Frf& h, const TwoMassFitOptions& options);

}  // namespace eol::analysis
