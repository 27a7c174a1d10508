#include "analysis/fit/added_inertia.h"

#include <Eigen/Dense>
#include <cmath>
#include <locale>
#include <sstream>

#include "analysis/fit/motional_jacobian.h"

namespace eol::analysis {

const FittedParameter* AddedInertiaSummary::Find(const std::string& name) const {
  for (const FittedParameter& p : estimates)
    if (p.name == name) return &p;
  return nullptr;
}

AddedInertiaSummary EstimateFromAddedInertia(const FitSummary& without, const FitSummary& with,
                                             double added_inertia_kg_m2,
                                             double added_inertia_sigma_kg_m2) {
  AddedInertiaSummary s;
  std::ostringstream os;
  os.imbue(std::locale::classic());
  os.precision(6);
  if (!without.usable || !with.usable || without.params.size() != kMotionalParamCount ||
      with.params.size() != kMotionalParamCount ||
      without.covariance.rows() != kMotionalParamCount) {
    s.message = "both fits must be usable one-mode fits with a covariance";
    return s;
  }
  if (!(std::isfinite(added_inertia_kg_m2) && added_inertia_kg_m2 > 0.0 &&
        std::isfinite(added_inertia_sigma_kg_m2) && added_inertia_sigma_kg_m2 >= 0.0)) {
    s.message = "the added inertia must be finite and positive (its sigma not negative)";
    return s;
  }
  const MotionalImpedance m0 = without.Model();
  const MotionalImpedance m1 = with.Model();
  const double r = std::pow(m0.f0_hz / m1.f0_hz, 2);
  if (!(r > 1.0)) {
    os << "the added inertia did not lower f0 (" << m0.f0_hz << " -> " << m1.f0_hz << " Hz)";
    s.message = os.str();
    return s;
  }
  s.params = FromMotional(m0, added_inertia_kg_m2 / (r - 1.0));

  // Log-space covariance of x = ln(Rp, f0, Q, f0', dJ).
  const int idx[3] = {kParamRp, kParamF0, kParamQ};
  const MotionalVector p0 = ToNaturalVector(m0);
  Eigen::Matrix<double, 5, 5> cx = Eigen::Matrix<double, 5, 5>::Zero();
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      cx(a, b) = without.covariance(idx[a], idx[b]) / (p0[idx[a]] * p0[idx[b]]);
  const double f1_sigma = with.params[kParamF0].sigma;
  cx(3, 3) = std::pow(f1_sigma / m1.f0_hz, 2);
  cx(4, 4) = std::pow(added_inertia_sigma_kg_m2 / added_inertia_kg_m2, 2);
  const double g = 2.0 * r / (r - 1.0);
  Eigen::Matrix<double, 4, 5> grad;
  grad << 0.0, -g, 0.0, g, 1.0,              // ln J_r
      0.0, g - 2.0, 0.0, -g, -1.0,           // ln C_m
      0.0, 1.0 - g, -1.0, g, 1.0,            // ln R_m
      0.5, (1.0 - g) / 2, -0.5, g / 2, 0.5;  // ln T
  const Eigen::Vector4d rel = (grad * cx * grad.transpose()).diagonal().cwiseSqrt();
  const double values[4] = {s.params.inertia_kg_m2, s.params.transmission_nm_per_a,
                            s.params.compliance_rad_per_nm, s.params.damping_nms_per_rad};
  const int row[4] = {0, 3, 1, 2};
  const char* names[4] = {"J_r_kg_m2", "T_nm_per_a", "Cm_rad_per_nm", "Rm_nms_per_rad"};
  const char* units[4] = {"kg m^2", "N m/A", "rad/(N m)", "N m s/rad"};
  for (int i = 0; i < 4; ++i)
    s.estimates.push_back({names[i], units[i], values[i], values[i] * rel[row[i]]});

  // Consistency: Rp' = Rp and Q' = Q f0 / f0'.
  const double rp_sigma = std::hypot(with.params[kParamRp].sigma, without.params[kParamRp].sigma);
  s.rp_consistency_z = (m1.rp_ohm - m0.rp_ohm) / rp_sigma;
  const double q_pred = m0.q * m0.f0_hz / m1.f0_hz;
  const double q_var = std::pow(with.params[kParamQ].sigma, 2) +
                       std::pow(q_pred, 2) * (cx(2, 2) + cx(1, 1) + cx(3, 3));
  s.q_consistency_z = (m1.q - q_pred) / std::sqrt(q_var);

  s.usable = true;
  os << "J_r = " << s.params.inertia_kg_m2 << " +- " << s.estimates[0].sigma << " kg m^2 from f0 "
     << m0.f0_hz << " -> " << m1.f0_hz << " Hz with dJ = " << added_inertia_kg_m2
     << " kg m^2; T = " << s.params.transmission_nm_per_a << " +- " << s.estimates[1].sigma
     << " N m/A; consistency z: Rp " << s.rp_consistency_z << ", Q " << s.q_consistency_z;
  if (std::abs(s.rp_consistency_z) > 3.0 || std::abs(s.q_consistency_z) > 3.0)
    os << " (beyond 3: the added inertia does not behave as a rigid addition to the mode)";
  s.message = os.str();
  return s;
}

}  // namespace eol::analysis
