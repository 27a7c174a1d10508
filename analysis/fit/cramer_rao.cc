#include "analysis/fit/cramer_rao.h"

#include <cmath>
#include <numbers>

namespace eol::analysis {

CramerRaoBound ComputeCramerRaoBound(const MotionalImpedance& truth,
                                     const std::vector<double>& freq_hz,
                                     const std::vector<double>& sigma) {
  CramerRaoBound b;
  if (freq_hz.empty() || sigma.size() != freq_hz.size()) {
    b.message = "need one sigma per line and at least one line (" + std::to_string(freq_hz.size()) +
                " lines, " + std::to_string(sigma.size()) + " sigmas)";
    return b;
  }
  const MotionalVector p = ToNaturalVector(truth);
  for (int i = 0; i < kMotionalParamCount; ++i) {
    if (!(std::isfinite(p[i]) && p[i] > 0.0)) {
      b.message = std::string("parameter ") + kMotionalParamNames[static_cast<std::size_t>(i)] +
                  " must be finite and positive";
      return b;
    }
  }
  std::vector<double> scale(freq_hz.size());
  for (std::size_t k = 0; k < freq_hz.size(); ++k) {
    if (!(std::isfinite(freq_hz[k]) && freq_hz[k] > 0.0) ||
        !(std::isfinite(sigma[k]) && sigma[k] > 0.0)) {
      b.message = "line " + std::to_string(k) + ": frequency and sigma must be finite and positive";
      return b;
    }
    scale[k] = std::numbers::sqrt2 / sigma[k];
  }

  Eigen::MatrixXd jacobian;
  MotionalJacobian(truth, freq_hz, scale, &jacobian);
  b.fisher = jacobian.transpose() * jacobian;
  MotionalMatrix c_log;
  if (!InvertInformation(b.fisher, &c_log)) {
    b.message = "Fisher matrix is singular: the lines do not determine all five parameters";
    return b;
  }
  b.covariance = LogToNaturalCovariance(truth, c_log);
  for (int i = 0; i < kMotionalParamCount; ++i)
    b.std_dev[static_cast<std::size_t>(i)] = std::sqrt(b.covariance(i, i));
  b.valid = true;
  b.message = "ok";
  return b;
}

CramerRaoBound ComputeCramerRaoBound(const MotionalImpedance& truth,
                                     const std::vector<double>& freq_hz, double sigma) {
  return ComputeCramerRaoBound(truth, freq_hz, std::vector<double>(freq_hz.size(), sigma));
}

namespace {
// N3 * SNR_pk of the closed forms.
double LinesTimesSnr(double f0_hz, double q, double rp_ohm, double line_spacing_hz,
                     double sigma_ohm) {
  const double b3db = f0_hz / q;
  const double n3 = b3db / line_spacing_hz;
  const double snr_pk = (rp_ohm * rp_ohm) / (sigma_ohm * sigma_ohm);
  return n3 * snr_pk;
}
}  // namespace

double CramerRaoF0ClosedFormHz(double f0_hz, double q, double rp_ohm, double line_spacing_hz,
                               double sigma_ohm) {
  const double b3db = f0_hz / q;
  return b3db / std::sqrt(2.0 * std::numbers::pi *
                          LinesTimesSnr(f0_hz, q, rp_ohm, line_spacing_hz, sigma_ohm));
}

double CramerRaoQRelativeClosedForm(double f0_hz, double q, double rp_ohm, double line_spacing_hz,
                                    double sigma_ohm) {
  return 2.0 /
         std::sqrt(std::numbers::pi * LinesTimesSnr(f0_hz, q, rp_ohm, line_spacing_hz, sigma_ohm));
}

}  // namespace eol::analysis
