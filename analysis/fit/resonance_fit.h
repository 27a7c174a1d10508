// Weighted maximum-likelihood fit of the clamped-motor impedance (NOTES.md section 4).
//
// Model: Z(f) = R + j w L + Rp / (1 + Q (j w/w0 + w0/(j w)))  (analysis/model/motor_model.h)
// Cost:  chi2 = sum_k |Z_k - Z(f_k; theta)|^2 / sigma_k^2  with sigma the complex std
//        (E|dZ|^2 = sigma^2), i.e. the negative log-likelihood of circular Gaussian noise.
// Start: a grid over (f0, Q) with R, L, Rp solved in closed form (variable projection).
// Finish: Levenberg-Marquardt on theta = ln(R, L, Rp, f0, Q).
// Covariance: (J^T W J)^-1 from the Jacobian at the optimum, mapped to natural units; when
// sigma is estimated from the data it is scaled by chi2/dof.
#pragma once

#include <Eigen/Dense>
#include <string>
#include <string_view>
#include <vector>

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
  int max_iterations = 200;

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
  std::string message;      // human-readable: what happened, or why not usable
  std::string termination;  // "converged", "max_iterations", "failed", "invalid_input"
  std::vector<FittedParameter> params;
  Eigen::MatrixXd covariance;  // of params, in their order, natural units
  double chi2 = 0.0;
  int dof = 0;
  double chi2_per_dof = 0.0;
  int iterations = 0;
  bool sigma_estimated = false;  // the Frf had no sigma: noise estimated from the residual

  const FittedParameter* Find(std::string_view name) const;
  MotionalImpedance Model() const;  // the fitted parameters as a model
};

// Never throws for bad data; returns usable == false with the reason.
FitSummary FitMotionalResonance(const Frf& z, const ResonanceFitOptions& options);

}  // namespace eol::analysis
