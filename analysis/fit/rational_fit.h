// Output-error fit of a rational transfer function to complex frequency-response data: the
// paper's route (section 3.2: MATLAB Ident's OE model in the frequency domain), kept for
// comparison with the physical ML fit (resonance_fit.h), which is sqrt(2) better in f0
// (analysis/README.md 4).
//
// Model, s = j 2 pi f:
//   H(s) = N(s) / D(s),  N(s) = sum_{i=0}^{nb} n_i s^i,  D(s) = sum_{i=0}^{na} d_i s^i,
// with one coefficient fixed to 1 to remove the common scale: n_0 (the paper's eq. 23 form
// of Y_e) or d_0 (eq. 22 form of H_m). The other nb + na + 1 coefficients are free.
// Cost (output error), per-line complex std sigma_k (E|dH|^2 = sigma_k^2):
//   chi2 = sum_k 2 |H(s_k) - H_k|^2 / sigma_k^2   (the residual convention of motional_jacobian.h)
// Start: Levy's linearised least squares (min sum |N - H_k D|^2 / sigma_k^2), then
// Sanathanan-Koerner iterations (the same, divided by |D_prev(s_k)|^2) until the coefficients
// settle. Finish: Levenberg-Marquardt (least_squares.h) on the output-error cost with the
// analytic Jacobian dH/dn_i = s^i / D, dH/dd_i = -N s^i / D^2.
// Numerics: coefficients are solved in the scaled variable s / w_ref, w_ref = 2 pi sqrt(f_min
// f_max), and reported for s in rad/s.
// Covariance of the free coefficients (J^T J)^-1 (scaled by the estimated noise variance when
// the data carry no sigma, as in resonance_fit.h).
#pragma once

#include <Eigen/Dense>
#include <complex>
#include <string>
#include <vector>

#include "analysis/fit/resonance_fit.h"

namespace eol::analysis {

enum class RationalNormalization {
  kNumeratorConstant,    // n_0 = 1
  kDenominatorConstant,  // d_0 = 1
};

struct RationalFitOptions {
  int numerator_order = 2;    // nb
  int denominator_order = 3;  // na
  RationalNormalization normalization = RationalNormalization::kNumeratorConstant;
  int sk_iterations = 30;
  int max_iterations = 300;  // Levenberg-Marquardt

  bool IsValid(std::string* why) const;
};

struct RationalFitSummary {
  bool usable = false;
  std::string message;
  Termination termination = Termination::kInvalidInput;
  Eigen::VectorXd numerator;    // n_0 .. n_nb, s in rad/s
  Eigen::VectorXd denominator;  // d_0 .. d_na
  // The free coefficients "n1".."d3" (the fixed one absent), with sigma; covariance in order.
  std::vector<FittedParameter> coefficients;
  Eigen::MatrixXd covariance;
  double chi2 = 0.0;
  int dof = 0;
  double chi2_per_dof = 0.0;
  int iterations = 0;  // Levenberg-Marquardt
  int sk_iterations = 0;
  bool sigma_estimated = false;

  std::complex<double> At(double f_hz) const;
  double Coefficient(const std::string& name) const;  // "n0", "d2", ...; NaN when absent
};

// sigma may be empty (noise estimated from the residual). Never throws for bad data.
RationalFitSummary FitRational(const std::vector<double>& freq_hz,
                               const std::vector<std::complex<double>>& value,
                               const std::vector<double>& sigma, const RationalFitOptions& options);

}  // namespace eol::analysis
