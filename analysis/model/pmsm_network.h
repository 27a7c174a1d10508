// The paper's lumped network of a PMSM under single-phase excitation, in physical parameters
// (the paper, eq. 3-30; analysis/README.md 1). Laplace variable s = j w, w = 2 pi f.
//
// Transducer (eq. 3-4): u = T(phi) * angular velocity, torque = T(phi) * i, with
// T(phi) = T_hat sin(p phi) (p pole pairs, phi the rotor position, eq. 1-2).
// Mechanical side seen by the torque (eq. 13): the torsional impedance
//   Z_m(s) = torque / angular velocity = 1/(s C_m) + R_m + s J_r,
// a rotor inertia J_r on a spring of compliance C_m (the cogging spring for a free shaft, the
// clamped rotor's first mode for a fixed shaft) with a damper R_m.
//
// Units: ohm, H, N m/A (= V s/rad), kg m^2, rad/(N m), N m s/rad.
#pragma once

#include <complex>
#include <string>

#include "analysis/model/motor_model.h"

namespace eol::analysis {

// T(phi) = T_hat sin(p phi), p = poles / 2 pole pairs, phi in radians from a position of no
// coupling (eq. 1-2). It vanishes at phi = k pi / p: no motional term, no information.
double TransmissionAtPosition(double t_hat_nm_per_a, int poles, double rotor_position_rad);

struct PmsmParams {
  double r_ohm = 0.0;                  // R: winding resistance of the phase pair
  double l_h = 0.0;                    // L(phi): inductance at the rotor position
  double transmission_nm_per_a = 0.0;  // T(phi)
  double inertia_kg_m2 = 0.0;          // J_r
  double compliance_rad_per_nm = 0.0;  // C_m (the ideal model of eq. 7 ignores it)
  double damping_nms_per_rad = 0.0;    // R_m (the ideal model ignores it)

  // False with the field named in *why unless R, L, T, J_r, C_m, R_m are finite and positive.
  bool IsValid(std::string* why) const;
};

// Ideal machine, eq. (7)-(8): no spring, no loss on the mechanical side.
//   Z(s) = R + s L + T^2 / (s J_r) = (T^2 + s R J_r + s^2 J_r L) / (s J_r)
//   Y(s) = 1 / Z(s) = s J_r / (T^2 + s R J_r + s^2 J_r L)
std::complex<double> IdealImpedance(const PmsmParams& p, double f_hz);
std::complex<double> IdealAdmittance(const PmsmParams& p, double f_hz);
// Eq. (9)-(10): the admittance pole pair of the ideal machine,
//   w0 = T / sqrt(J_r L),   xi = (R / (2 T)) sqrt(J_r / L).
double IdealPoleFrequencyHz(const PmsmParams& p);
double IdealPoleDamping(const PmsmParams& p);

// Eq. (13): Z_m(s) = 1/(s C_m) + R_m + s J_r   (N m s/rad).
std::complex<double> TorsionalImpedance(const PmsmParams& p, double f_hz);
// Eq. (12), (14): Z_e(s) = R + s L + T^2 / Z_m(s)
//   = (R + s (C_m R_m R + L + T^2 C_m) + s^2 C_m (J_r R + R_m L) + s^3 J_r C_m L)
//     / (1 + s C_m R_m + s^2 J_r C_m)
std::complex<double> ElectricalImpedance(const PmsmParams& p, double f_hz);
// Eq. (15): Y_e(s) = 1 / Z_e(s).
std::complex<double> ElectricalAdmittance(const PmsmParams& p, double f_hz);
// Eq. (19)-(20): H_m(s) = beta / I = s T / Z_m(s)
//   = s^2 T C_m / (1 + s R_m C_m + s^2 J_r C_m)   (rad/s^2 per A).
std::complex<double> MechanicalTransfer(const PmsmParams& p, double f_hz);

// Eq. (16)-(18), losses removed (R = R_m = 0):
//   admittance pole  w_p = sqrt((L + T^2 C_m) / (J_r C_m L))   (|Z_e| = 0, the series resonance)
//   admittance zero  w_z = 1 / sqrt(J_r C_m)                    (|Z_e| = inf, the motional peak)
double UndampedPoleFrequencyHz(const PmsmParams& p);
double UndampedZeroFrequencyHz(const PmsmParams& p);

// The five combinations Z identifies (analysis/README.md 1; motor_model.h):
//   Rp = T^2 / R_m,  f0 = 1 / (2 pi sqrt(J_r C_m)),  Q = sqrt(J_r / C_m) / R_m,  R, L.
MotionalImpedance ToMotional(const PmsmParams& p);
// And back, with J_r given from elsewhere (the sixth parameter Z cannot identify):
//   C_m = 1 / (J_r w0^2),  R_m = J_r w0 / Q,  T = sqrt(Rp R_m).
PmsmParams FromMotional(const MotionalImpedance& m, double inertia_kg_m2);

// The normalised transfer-function coefficients of eq. (22)-(23):
//   H_m(s) = (D1 + D2 s + D3 s^2) / (1 + C2 s + C3 s^2)
//     D1 = D2 = 0,  D3 = T C_m,  C2 = R_m C_m,  C3 = J_r C_m
//   Y_e(s) = (1 + B2 s + B3 s^2) / (A1 + A2 s + A3 s^2 + A4 s^3)
//     B2 = C_m R_m,  B3 = J_r C_m,  A1 = R,  A2 = C_m R_m R + L + T^2 C_m,
//     A3 = C_m (J_r R + R_m L),  A4 = J_r C_m L
struct MechanicalCoefficients {
  double d1 = 0.0, d2 = 0.0, d3 = 0.0;
  double c2 = 0.0, c3 = 0.0;
};
struct AdmittanceCoefficients {
  double b2 = 0.0, b3 = 0.0;
  double a1 = 0.0, a2 = 0.0, a3 = 0.0, a4 = 0.0;
};
MechanicalCoefficients ToMechanicalCoefficients(const PmsmParams& p);
AdmittanceCoefficients ToAdmittanceCoefficients(const PmsmParams& p);

// Eq. (24)-(26), J_r given: T = D3 J_r / C3,  C_m = C3 / J_r,  R_m = C2 J_r / C3.
// R and L are not in H_m: they are returned as 0.
PmsmParams FromMechanicalCoefficients(const MechanicalCoefficients& c, double inertia_kg_m2);
// Eq. (27)-(30), J_r given: R = A1,  L = A4 / B3,  T = sqrt((J_r / B3)(A2 - A1 B2 - A4 / B3)),
// C_m = B3 / J_r,  R_m = B2 J_r / B3. T is NaN when the radicand is negative (the data do not
// fit the model). A3 is not used: it is fixed by the others,
//   A3 = B3 A1 + B2 A4 / B3   (AdmittanceConstraint returns A3 minus this; 0 for the model).
PmsmParams FromAdmittanceCoefficients(const AdmittanceCoefficients& c, double inertia_kg_m2);
double AdmittanceConstraint(const AdmittanceCoefficients& c);

}  // namespace eol::analysis
