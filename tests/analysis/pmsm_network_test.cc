// Known answers for the paper's network (analysis/model/pmsm_network.h): eq. 7-10, 12-18,
// 20, 22-23 and the eq. 24-30 mapping round trip.
#include "analysis/model/pmsm_network.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "tests/support/paper_motor.h"

namespace eol::analysis {
namespace {

using Cplx = std::complex<double>;
constexpr double kPi = std::numbers::pi;

PmsmParams Motor() { return testing::PaperMotor(); }

void ExpectRelNear(double a, double b, double rel) { EXPECT_NEAR(a, b, rel * std::abs(b)); }
void ExpectRelNear(Cplx a, Cplx b, double rel) { EXPECT_LE(std::abs(a - b), rel * std::abs(b)); }

TEST(PmsmNetwork, TransmissionFollowsRotorPosition) {
  EXPECT_NEAR(TransmissionAtPosition(0.05, 10, 18.0 * kPi / 180.0), 0.05, 1e-15);
  EXPECT_NEAR(TransmissionAtPosition(0.05, 10, 36.0 * kPi / 180.0), 0.0, 1e-15);
  EXPECT_NEAR(TransmissionAtPosition(0.05, 10, 6.0 * kPi / 180.0), 0.05 * std::sin(kPi / 6), 1e-15);
}

TEST(PmsmNetwork, IdealModelEq7To10) {
  const PmsmParams p = Motor();
  for (double f : {50.0, 390.0, 1000.0}) {
    const Cplx s(0, 2 * kPi * f);
    const double t2 = p.transmission_nm_per_a * p.transmission_nm_per_a;
    // Eq. 7, second form.
    const Cplx z7 = (t2 + s * p.r_ohm * p.inertia_kg_m2 + s * s * p.inertia_kg_m2 * p.l_h) /
                    (s * p.inertia_kg_m2);
    ExpectRelNear(IdealImpedance(p, f), z7, 1e-14);
    ExpectRelNear(IdealAdmittance(p, f) * IdealImpedance(p, f), Cplx(1.0), 1e-14);
  }
  // Eq. 9: the series resonance of L with the capacitor J/T^2.
  const double w0 = 2 * kPi * IdealPoleFrequencyHz(p);
  ExpectRelNear(w0 * w0, std::pow(p.transmission_nm_per_a, 2) / (p.inertia_kg_m2 * p.l_h), 1e-14);
  ExpectRelNear(IdealImpedance(p, w0 / (2 * kPi)), Cplx(p.r_ohm), 1e-12);  // reactances cancel
  // Eq. 10: xi = R / (2 sqrt(L / C_el)) with C_el = J / T^2.
  const double c_el = p.inertia_kg_m2 / std::pow(p.transmission_nm_per_a, 2);
  ExpectRelNear(IdealPoleDamping(p), p.r_ohm / 2 * std::sqrt(c_el / p.l_h), 1e-14);
}

TEST(PmsmNetwork, NonIdealModelEq12To15AndMechanicalEq20) {
  const PmsmParams p = Motor();
  const AdmittanceCoefficients a = ToAdmittanceCoefficients(p);
  const MechanicalCoefficients m = ToMechanicalCoefficients(p);
  for (double f : {10.0, 200.0, 390.0, 391.3, 800.0, 5000.0}) {
    const Cplx s(0, 2 * kPi * f);
    // Eq. 14 as the ratio of its polynomials (the coefficients of eq. 23).
    const Cplx num = a.a1 + a.a2 * s + a.a3 * s * s + a.a4 * s * s * s;
    const Cplx den = 1.0 + a.b2 * s + a.b3 * s * s;
    ExpectRelNear(ElectricalImpedance(p, f), num / den, 1e-12);
    ExpectRelNear(ElectricalAdmittance(p, f), den / num, 1e-12);
    // Eq. 20/22.
    ExpectRelNear(MechanicalTransfer(p, f),
                  (m.d1 + m.d2 * s + m.d3 * s * s) / (1.0 + m.c2 * s + m.c3 * s * s), 1e-12);
    // Eq. 19: H_m = s T / Z_m.
    ExpectRelNear(MechanicalTransfer(p, f), s * p.transmission_nm_per_a / TorsionalImpedance(p, f),
                  1e-14);
    // The station's parallel R-L-C form is the same network.
    ExpectRelNear(ToMotional(p).At(f), ElectricalImpedance(p, f), 1e-12);
  }
  EXPECT_NEAR(AdmittanceConstraint(a), 0.0, 1e-15 * std::abs(a.a3));
}

TEST(PmsmNetwork, UndampedPoleAndZeroEq16To18) {
  PmsmParams p = Motor();
  const double fz = UndampedZeroFrequencyHz(p);
  const double fp = UndampedPoleFrequencyHz(p);
  EXPECT_NEAR(fz, 390.0, 1e-9);
  // Closed forms.
  const double c = p.compliance_rad_per_nm, j = p.inertia_kg_m2, l = p.l_h;
  const double t2 = std::pow(p.transmission_nm_per_a, 2);
  ExpectRelNear(2 * kPi * fp, std::sqrt((l + t2 * c) / (j * c * l)), 1e-14);
  // Losses removed: eq. 16's numerator vanishes at w_z and its denominator at w_p.
  p.r_ohm = 0.0;
  p.damping_nms_per_rad = 0.0;
  const AdmittanceCoefficients a = ToAdmittanceCoefficients(p);
  const double wz = 2 * kPi * fz, wp = 2 * kPi * fp;
  EXPECT_NEAR(1.0 - a.b3 * wz * wz, 0.0, 1e-12);
  EXPECT_NEAR(a.a2 - a.a4 * wp * wp, 0.0, 1e-12 * a.a2);
  // The pole sits above the zero: the motional capacitor J/T^2 in series with L.
  EXPECT_GT(fp, fz);
  // Nearly lossless: |Z_e| is huge at the zero and tiny at the pole.
  p.damping_nms_per_rad = 1e-12;
  EXPECT_GT(std::abs(ElectricalImpedance(p, fz)), 1e6);
  EXPECT_LT(std::abs(ElectricalImpedance(p, fp)), 1e-6);
}

TEST(PmsmNetwork, MotionalMappingBothWays) {
  const PmsmParams p = Motor();
  const MotionalImpedance m = ToMotional(p);
  EXPECT_NEAR(m.f0_hz, 390.0, 1e-9);
  EXPECT_NEAR(m.q, 50.0, 1e-12);
  ExpectRelNear(m.rp_ohm, std::pow(p.transmission_nm_per_a, 2) / p.damping_nms_per_rad, 1e-15);
  const PmsmParams back = FromMotional(m, p.inertia_kg_m2);
  ExpectRelNear(back.r_ohm, p.r_ohm, 1e-14);
  ExpectRelNear(back.l_h, p.l_h, 1e-14);
  ExpectRelNear(back.transmission_nm_per_a, p.transmission_nm_per_a, 1e-14);
  ExpectRelNear(back.compliance_rad_per_nm, p.compliance_rad_per_nm, 1e-14);
  ExpectRelNear(back.damping_nms_per_rad, p.damping_nms_per_rad, 1e-14);
}

TEST(PmsmNetwork, Eq24To30RoundTrip) {
  PmsmParams p = Motor();
  for (double t : {0.05, 0.013, 0.2}) {
    p.transmission_nm_per_a = t;
    const PmsmParams e = FromAdmittanceCoefficients(ToAdmittanceCoefficients(p), p.inertia_kg_m2);
    ExpectRelNear(e.r_ohm, p.r_ohm, 1e-9);
    ExpectRelNear(e.l_h, p.l_h, 1e-9);
    ExpectRelNear(e.transmission_nm_per_a, p.transmission_nm_per_a, 1e-9);
    ExpectRelNear(e.compliance_rad_per_nm, p.compliance_rad_per_nm, 1e-9);
    ExpectRelNear(e.damping_nms_per_rad, p.damping_nms_per_rad, 1e-9);
    const PmsmParams h = FromMechanicalCoefficients(ToMechanicalCoefficients(p), p.inertia_kg_m2);
    ExpectRelNear(h.transmission_nm_per_a, p.transmission_nm_per_a, 1e-9);
    ExpectRelNear(h.compliance_rad_per_nm, p.compliance_rad_per_nm, 1e-9);
    ExpectRelNear(h.damping_nms_per_rad, p.damping_nms_per_rad, 1e-9);
  }
  // A negative radicand in eq. 28 gives NaN, not a made-up T.
  AdmittanceCoefficients bad = ToAdmittanceCoefficients(p);
  bad.a2 = 0.0;
  EXPECT_TRUE(std::isnan(FromAdmittanceCoefficients(bad, p.inertia_kg_m2).transmission_nm_per_a));
}

TEST(PmsmNetwork, ValidationNamesTheField) {
  PmsmParams p = Motor();
  std::string why;
  EXPECT_TRUE(p.IsValid(&why));
  p.compliance_rad_per_nm = -1.0;
  EXPECT_FALSE(p.IsValid(&why));
  EXPECT_NE(why.find("compliance_rad_per_nm"), std::string::npos);
}

}  // namespace
}  // namespace eol::analysis
