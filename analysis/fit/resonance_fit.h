// Weighted maximum-likelihood fit of the clamped-motor impedance (analysis/README.md section 4).
//
// Model: Z(f) = R + j w L + Rp / (1 + Q (j w/w0 + w0/(j w)))  (analysis/model/motor_model.h)
// Cost:  chi2 = sum_i r_i^2 = 2 sum_k |Z_k - Z(f_k; theta)|^2 / sigma_k^2, with sigma_k the
//        complex std (E|dZ|^2 = sigma^2) and r the real residual of motional_jacobian.h:
//        Re and Im of sqrt(2) (Z(f_k) - Z_k) / sigma_k, each of unit variance. This is twice
//        the negative log-likelihood of circular Gaussian noise (up to a constant), and it
//        follows a chi-square law with dof = 2K - 5 (K lines), so chi2_per_dof ~ 1 when the
//        noise matches sigma and the model is right (analysis/README.md 4: "about 2F - n_params").
// Start: a grid over (f0, Q), f0 log-spaced over [f0_min_hz, f0_max_hz], Q log-spaced over
//        [q_min, q_max]; at each point R, L, Rp are solved by weighted linear least squares
//        (Z is linear in them for fixed f0, Q: variable projection) and only points with
//        R, L, Rp > 0 count. Two finer 21 x 21 grids around the best cell follow.
// Finish: Levenberg-Marquardt (MINPACK, Eigen's unsupported NonLinearOptimization) on
//        theta = ln(R, L, Rp, f0, Q) with the analytic Jacobian of motional_jacobian.h.
// Covariance: (Jr^T Jr)^-1 in theta, Jr the Jacobian of r at the optimum, mapped to natural
//        units as diag(p) C diag(p) (sigma_p = p sigma_ln_p).
// Without sigma: the fit uses unit weights, the noise is estimated from the residual as
//        sigma^2 = chi2(sigma = 1) / dof, the covariance is scaled by it (so chi2_per_dof is
//        1 by construction) and sigma_estimated is set.
//
// usable == false (params filled when a fit was made, for diagnosis) when:
//   - the input is bad (termination kInvalidInput): Frf::Validate fails, the quantity is not
//     impedance, fewer than 2 x 5 lines, or invalid options;
//   - no resonance was found between f0_min and f0_max: the fitted f0 is outside the search
//     range or within one coarse grid step of its edges, or Rp is not significant
//     (Rp / sigma_Rp < min_rp_significance, e.g. T(phi) ~ 0, no coupling);
//   - the covariance is not finite (singular Jacobian);
//   - Levenberg-Marquardt failed or ran out of iterations.
#pragma once

#include <Eigen/Dense>
#include <string>
#include <string_view>
#include <vector>

#include "analysis/fit/least_squares.h"
#include "analysis/frf.h"
#include "analysis/model/motor_model.h"

namespace eol::analysis {

struct ResonanceFitOptions {
  double f0_min_hz = 0.0;  // search range of the motional resonance; 0 = the data's band
  double f0_max_hz = 0.0;
  double q_min = 2.0;
  double q_max = 1000.0;
  int grid_f0 = 300;
  int grid_q = 24;
  int max_iterations = 200;  // Levenberg-Marquardt iterations (successful steps)
  // The motional peak must stand this many standard deviations above zero (Rp / sigma_Rp);
  // below it the fit reports "no resonance found".
  double min_rp_significance = 5.0;
  // AnalyzeImpedance (impedance_analysis.h) also tests for a second motional mode and reports
  // second_mode_chi2_drop; set by a recipe that declares a limit on it (costs a two-mode fit,
  // modes_fit.h: about 35 ms on 601 lines).
  bool second_mode_test = false;

  bool IsValid(std::string* why) const;
};

struct FittedParameter {
  std::string name;  // R_ohm, L_h, Rp_ohm, f0_hz, Q
  std::string unit;
  double value = 0.0;
  double sigma = 0.0;
};

struct FitSummary {
  std::string model = "R+sL+parallel-RLC";
  bool usable = false;
  std::string message;  // human-readable: what happened, or why not usable
  Termination termination = Termination::kInvalidInput;
  std::vector<FittedParameter> params;
  Eigen::MatrixXd covariance;  // of params, in their order, natural units
  double chi2 = 0.0;
  int dof = 0;
  double chi2_per_dof = 0.0;
  int iterations = 0;
  bool sigma_estimated = false;  // the Frf had no sigma: noise estimated from the residual
  double estimated_sigma = 0.0;  // complex std per line estimated when sigma_estimated, ohm

  const FittedParameter* Find(std::string_view name) const;  // nullptr when absent
  MotionalImpedance Model() const;  // the fitted parameters as a model (zeros if none)
};

// Never throws for bad data; returns usable == false with the reason.
FitSummary FitMotionalResonance(const Frf& z, const ResonanceFitOptions& options);

}  // namespace eol::analysis
