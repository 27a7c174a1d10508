// The clamped-motor impedance and its analytic derivatives with respect to the log parameters.
// The one place these derivatives live: FitMotionalResonance (resonance_fit.h) and the
// Cramer-Rao bound (cramer_rao.h) both call it, so the fit and its bound cannot drift apart.
//
// Model (analysis/model/motor_model.h), w = 2 pi f, w0 = 2 pi f0:
//   Z(f) = R + j w L + Rp / D,   D = 1 + Q (j w/w0 + w0/(j w)) = 1 + j Q x,   x = w/w0 - w0/w
// Parameters theta = ln(R, L, Rp, f0, Q) (all five must be positive). Derivatives:
//   dZ/d ln R  = R
//   dZ/d ln L  = j w L
//   dZ/d ln Rp = Rp / D
//   dZ/d ln f0 = j Q Rp (w/w0 + w0/w) / D^2      (d ln w0 = d ln f0)
//   dZ/d ln Q  = -j Q x Rp / D^2
//
// Weighted real residual, the convention of the whole fit module: for line k with complex
// noise std sigma_k (E|dZ|^2 = sigma_k^2, so Re and Im each have variance sigma_k^2 / 2),
//   r_{2k}   = s_k Re(Z(f_k; theta) - Z_k),   r_{2k+1} = s_k Im(Z(f_k; theta) - Z_k),
//   s_k = sqrt(2) / sigma_k.
// Each r_i then has unit variance, chi2 = |r|^2 = 2 sum_k |Z(f_k) - Z_k|^2 / sigma_k^2 follows a
// chi-square law with 2K - 5 degrees of freedom at the optimum, and the stacked Jacobian Jr of
// r gives the Fisher matrix F = Jr^T Jr = sum_k (2 / sigma_k^2) Re(J_k^H J_k) (analysis/README.md
// 4).
#pragma once

#include <Eigen/Dense>
#include <array>
#include <complex>
#include <vector>

#include "analysis/model/motor_model.h"

namespace eol::analysis {

inline constexpr int kMotionalParamCount = 5;

// Index of each parameter in theta, in covariance matrices and in FitSummary::params.
enum MotionalParam : int { kParamR = 0, kParamL = 1, kParamRp = 2, kParamF0 = 3, kParamQ = 4 };

// Names and units in MotionalParam order: R_ohm (ohm), L_h (H), Rp_ohm (ohm), f0_hz (Hz), Q (1).
extern const std::array<const char*, kMotionalParamCount> kMotionalParamNames;
extern const std::array<const char*, kMotionalParamCount> kMotionalParamUnits;

using MotionalVector = Eigen::Matrix<double, kMotionalParamCount, 1>;
using MotionalMatrix = Eigen::Matrix<double, kMotionalParamCount, kMotionalParamCount>;

// Natural parameters (ohm, H, ohm, Hz, 1) in MotionalParam order, and back.
MotionalVector ToNaturalVector(const MotionalImpedance& p);
MotionalImpedance FromNaturalVector(const MotionalVector& v);
// theta = ln of the natural parameters (all must be positive), and back.
MotionalVector ToLogParams(const MotionalImpedance& p);
MotionalImpedance FromLogParams(const MotionalVector& theta);

// Z(f) and dZ/dtheta at one frequency.
struct MotionalPoint {
  std::complex<double> z;
  std::array<std::complex<double>, kMotionalParamCount> dz_dtheta;
};
MotionalPoint EvaluateMotional(const MotionalImpedance& p, double f_hz);

// The weighted real residual r (length 2K, see above) of the model p against `value` on
// `freq_hz`, with per-line scale s_k = `scale`[k] (sqrt(2)/sigma_k). All three vectors have
// length K. *r is resized.
void MotionalResidual(const MotionalImpedance& p, const std::vector<double>& freq_hz,
                      const std::vector<std::complex<double>>& value,
                      const std::vector<double>& scale, Eigen::VectorXd* r);

// The Jacobian dr/dtheta (2K x 5) of that residual; it does not depend on the data.
// *jacobian is resized.
void MotionalJacobian(const MotionalImpedance& p, const std::vector<double>& freq_hz,
                      const std::vector<double>& scale, Eigen::MatrixXd* jacobian);

// Inverse of an information matrix Jr^T Jr (theta = ln p). Returns false, leaving *inverse
// untouched, when it is not positive definite or, scaled to unit diagonal, has a smallest
// eigenvalue below 1e-13 of the largest: the data do not determine all five parameters.
bool InvertInformation(const MotionalMatrix& information, MotionalMatrix* inverse);

// Covariance in theta = ln p mapped to natural units: diag(p) C diag(p)
// (first order: sigma_p = p sigma_ln_p).
MotionalMatrix LogToNaturalCovariance(const MotionalImpedance& p, const MotionalMatrix& c_log);

}  // namespace eol::analysis
