#include "analysis/model/pmsm_network.h"

#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

namespace eol::analysis {
namespace {

using Cplx = std::complex<double>;

Cplx S(double f_hz) { return {0.0, 2.0 * std::numbers::pi * f_hz}; }

}  // namespace

double TransmissionAtPosition(double t_hat_nm_per_a, int poles, double rotor_position_rad) {
  return t_hat_nm_per_a * std::sin(0.5 * poles * rotor_position_rad);
}

bool PmsmParams::IsValid(std::string* why) const {
  const std::pair<const char*, double> fields[] = {{"r_ohm", r_ohm},
                                                   {"l_h", l_h},
                                                   {"transmission_nm_per_a", transmission_nm_per_a},
                                                   {"inertia_kg_m2", inertia_kg_m2},
                                                   {"compliance_rad_per_nm", compliance_rad_per_nm},
                                                   {"damping_nms_per_rad", damping_nms_per_rad}};
  for (const auto& [name, v] : fields) {
    if (!(std::isfinite(v) && v > 0.0)) {
      if (why) *why = std::string(name) + " must be finite and positive";
      return false;
    }
  }
  return true;
}

Cplx IdealImpedance(const PmsmParams& p, double f_hz) {
  const Cplx s = S(f_hz);
  const double t2 = p.transmission_nm_per_a * p.transmission_nm_per_a;
  return p.r_ohm + s * p.l_h + t2 / (s * p.inertia_kg_m2);
}

Cplx IdealAdmittance(const PmsmParams& p, double f_hz) {
  const Cplx s = S(f_hz);
  const double t2 = p.transmission_nm_per_a * p.transmission_nm_per_a;
  const double j = p.inertia_kg_m2;
  return s * j / (t2 + s * p.r_ohm * j + s * s * j * p.l_h);
}

double IdealPoleFrequencyHz(const PmsmParams& p) {
  return p.transmission_nm_per_a / std::sqrt(p.inertia_kg_m2 * p.l_h) / (2.0 * std::numbers::pi);
}

double IdealPoleDamping(const PmsmParams& p) {
  return p.r_ohm / (2.0 * p.transmission_nm_per_a) * std::sqrt(p.inertia_kg_m2 / p.l_h);
}

Cplx TorsionalImpedance(const PmsmParams& p, double f_hz) {
  const Cplx s = S(f_hz);
  return 1.0 / (s * p.compliance_rad_per_nm) + p.damping_nms_per_rad + s * p.inertia_kg_m2;
}

Cplx ElectricalImpedance(const PmsmParams& p, double f_hz) {
  const double t2 = p.transmission_nm_per_a * p.transmission_nm_per_a;
  return p.r_ohm + S(f_hz) * p.l_h + t2 / TorsionalImpedance(p, f_hz);
}

Cplx ElectricalAdmittance(const PmsmParams& p, double f_hz) {
  return 1.0 / ElectricalImpedance(p, f_hz);
}

Cplx MechanicalTransfer(const PmsmParams& p, double f_hz) {
  return S(f_hz) * p.transmission_nm_per_a / TorsionalImpedance(p, f_hz);
}

double UndampedPoleFrequencyHz(const PmsmParams& p) {
  const double c = p.compliance_rad_per_nm;
  const double t2 = p.transmission_nm_per_a * p.transmission_nm_per_a;
  return std::sqrt((p.l_h + t2 * c) / (p.inertia_kg_m2 * c * p.l_h)) / (2.0 * std::numbers::pi);
}

double UndampedZeroFrequencyHz(const PmsmParams& p) {
  return 1.0 / std::sqrt(p.inertia_kg_m2 * p.compliance_rad_per_nm) / (2.0 * std::numbers::pi);
}

MotionalImpedance ToMotional(const PmsmParams& p) {
  MotionalImpedance m;
  m.r_ohm = p.r_ohm;
  m.l_h = p.l_h;
  m.rp_ohm = p.transmission_nm_per_a * p.transmission_nm_per_a / p.damping_nms_per_rad;
  m.f0_hz = UndampedZeroFrequencyHz(p);
  m.q = std::sqrt(p.inertia_kg_m2 / p.compliance_rad_per_nm) / p.damping_nms_per_rad;
  return m;
}

PmsmParams FromMotional(const MotionalImpedance& m, double inertia_kg_m2) {
  const double w0 = 2.0 * std::numbers::pi * m.f0_hz;
  PmsmParams p;
  p.r_ohm = m.r_ohm;
  p.l_h = m.l_h;
  p.inertia_kg_m2 = inertia_kg_m2;
  p.compliance_rad_per_nm = 1.0 / (inertia_kg_m2 * w0 * w0);
  p.damping_nms_per_rad = inertia_kg_m2 * w0 / m.q;
  p.transmission_nm_per_a = std::sqrt(m.rp_ohm * p.damping_nms_per_rad);
  return p;
}

MechanicalCoefficients ToMechanicalCoefficients(const PmsmParams& p) {
  MechanicalCoefficients c;
  c.d3 = p.transmission_nm_per_a * p.compliance_rad_per_nm;
  c.c2 = p.damping_nms_per_rad * p.compliance_rad_per_nm;
  c.c3 = p.inertia_kg_m2 * p.compliance_rad_per_nm;
  return c;
}

AdmittanceCoefficients ToAdmittanceCoefficients(const PmsmParams& p) {
  const double cm = p.compliance_rad_per_nm;
  const double rm = p.damping_nms_per_rad;
  const double j = p.inertia_kg_m2;
  const double t2 = p.transmission_nm_per_a * p.transmission_nm_per_a;
  AdmittanceCoefficients c;
  c.b2 = cm * rm;
  c.b3 = j * cm;
  c.a1 = p.r_ohm;
  c.a2 = cm * rm * p.r_ohm + p.l_h + t2 * cm;
  c.a3 = cm * (j * p.r_ohm + rm * p.l_h);
  c.a4 = j * cm * p.l_h;
  return c;
}

PmsmParams FromMechanicalCoefficients(const MechanicalCoefficients& c, double inertia_kg_m2) {
  PmsmParams p;
  p.inertia_kg_m2 = inertia_kg_m2;
  p.transmission_nm_per_a = c.d3 / c.c3 * inertia_kg_m2;
  p.compliance_rad_per_nm = c.c3 / inertia_kg_m2;
  p.damping_nms_per_rad = c.c2 / c.c3 * inertia_kg_m2;
  return p;
}

PmsmParams FromAdmittanceCoefficients(const AdmittanceCoefficients& c, double inertia_kg_m2) {
  PmsmParams p;
  p.inertia_kg_m2 = inertia_kg_m2;
  p.r_ohm = c.a1;
  p.l_h = c.a4 / c.b3;
  const double radicand = inertia_kg_m2 / c.b3 * (c.a2 - c.a1 * c.b2 - c.a4 / c.b3);
  p.transmission_nm_per_a =
      radicand >= 0.0 ? std::sqrt(radicand) : std::numeric_limits<double>::quiet_NaN();
  p.compliance_rad_per_nm = c.b3 / inertia_kg_m2;
  p.damping_nms_per_rad = c.b2 * inertia_kg_m2 / c.b3;
  return p;
}

double AdmittanceConstraint(const AdmittanceCoefficients& c) {
  return c.a3 - (c.b3 * c.a1 + c.b2 * c.a4 / c.b3);
}

}  // namespace eol::analysis
