// Cramer-Rao bound of the clamped-motor impedance fit (analysis/README.md section 4).
//
// Model and parameters as in resonance_fit.h: Z(f) = R + j w L + Rp / (1 + Q (j w/w0 + w0/(j w))),
// theta = ln(R, L, Rp, f0, Q). With circular complex Gaussian noise of std sigma_k on line k
// (E|dZ|^2 = sigma_k^2) the Fisher information is
//   F = sum_k (2 / sigma_k^2) Re(J_k^H J_k),   J_k = dZ(f_k) / dtheta  (1 x 5, complex),
// which is Jr^T Jr for the weighted real residual the fit minimises (motional_jacobian.h, the
// same derivative code). Any unbiased estimator has cov(theta) >= F^-1; in natural units
// cov(p) >= diag(p) F^-1 diag(p), so std(p_i) >= p_i sqrt((F^-1)_ii).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "analysis/fit/motional_jacobian.h"
#include "analysis/model/motor_model.h"

namespace eol::analysis {

struct CramerRaoBound {
  bool valid = false;  // false: bad input or singular Fisher matrix (see message)
  std::string message;
  MotionalMatrix fisher = MotionalMatrix::Zero();  // in theta = ln p
  MotionalMatrix covariance =
      MotionalMatrix::Zero();  // bound in natural units, MotionalParam order
  // Standard deviation at the bound, natural units (ohm, H, ohm, Hz, 1), index MotionalParam.
  std::array<double, kMotionalParamCount> std_dev{};

  double Std(MotionalParam i) const { return std_dev[static_cast<std::size_t>(i)]; }
};

// The bound at the true parameters `truth` (all positive) for lines freq_hz (Hz, positive)
// with per-line complex noise std sigma (ohm, positive, same length as freq_hz).
CramerRaoBound ComputeCramerRaoBound(const MotionalImpedance& truth,
                                     const std::vector<double>& freq_hz,
                                     const std::vector<double>& sigma);
// Same, with one sigma (ohm) for every line.
CramerRaoBound ComputeCramerRaoBound(const MotionalImpedance& truth,
                                     const std::vector<double>& freq_hz, double sigma);

// Closed forms for one lightly damped mode (analysis/README.md 4), uniform line spacing df (Hz) and
// per-line complex noise std sigma (ohm), with B3dB = f0 / Q, N3 = B3dB / df lines in the
// half-power band and SNR_pk = Rp^2 / sigma^2. They assume the peak is well inside the band
// and the background R + j w L is pinned down by the lines around it.
//   structure known:   std(f0)       = B3dB / sqrt(2 pi N3 SNR_pk)   (Hz)
double CramerRaoF0ClosedFormHz(double f0_hz, double q, double rp_ohm, double line_spacing_hz,
                               double sigma_ohm);
//   Rp free:           std(Q) / Q    = std(zeta) / zeta = 2 / sqrt(pi N3 SNR_pk)   (1)
double CramerRaoQRelativeClosedForm(double f0_hz, double q, double rp_ohm, double line_spacing_hz,
                                    double sigma_ohm);

}  // namespace eol::analysis
