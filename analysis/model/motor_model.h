// The clamped motor seen from one stator phase pair (the paper, eq. 12-14, analysis/README.md 1-2).
#pragma once

#include <complex>
#include <limits>
#include <vector>

#include "analysis/frf.h"

namespace eol::analysis {

// Electrical impedance with the motional term written as a parallel R-L-C:
//   Z(s) = R + s L + Zp(s),     Zp(s) = Rp / (1 + Q (s/w0 + w0/s)),   w0 = 2 pi f0
// This is eq. (14) rearranged: Zp = T^2 / Z_m with Z_m = k/s + R_m + s J, so
//   Rp = T^2 / R_m,  Lp = T^2 / k,  Cp = J / T^2,  w0 = sqrt(k / J),  Q = sqrt(J k) / R_m.
// Only these five combinations are identifiable from Z alone (analysis/README.md 1).
// Re Z peaks at f0 with height R + Rp; |Z| peaks slightly below f0 (inductive background).
struct MotionalImpedance {
  double r_ohm = 0.0;
  double l_h = 0.0;
  double rp_ohm = 0.0;
  double f0_hz = 0.0;
  double q = 0.0;

  std::complex<double> At(double f_hz) const;
  Frf Evaluate(const std::vector<double>& freq_hz) const;  // method "model", no sigma
  // The mode's residue T^2 / J = Rp w0 / Q (ohm/s): the inverse of the inertia that follows
  // the magnets, where the torque acts, scaled by T^2. Loosening a magnet's bond lets less
  // inertia follow it, so the residue rises: about twelve times faster, in relative terms, than
  // the resonance falls (tests/peers/independent_population.py's chain, all ten bonds at a
  // stiffness loss of 0.8: f0 -0.9 %, residue +10 %), while the fixture moves f0 but hardly
  // the residue (the whole rotor follows a soft clamp alike).
  double ResidueOhmPerS() const;
};

// The fixed-shaft torsional system reduced to its first mode: the rotor (magnets and poles,
// inertia J on the bond and bridge spring k_rotor) in series with the shaft-end fixture
// spring k_fixture:
//   k_eff = k_rotor k_fixture / (k_rotor + k_fixture),   f0 = sqrt(k_eff / J) / (2 pi)
// Damping is given as the mode's quality factor Q = sqrt(J k_eff) / R_m.
// A rigid fixture is k_fixture = +inf. Units: kg m^2, N m/rad, N m/A.
struct ClampedRotor {
  double inertia_kg_m2 = 0.0;
  double k_rotor_nm_per_rad = 0.0;
  double k_fixture_nm_per_rad = std::numeric_limits<double>::infinity();
  double q = 50.0;
  double transmission_nm_per_a = 0.0;  // T(phi) at the clamped rotor position

  double EffectiveStiffnessNmPerRad() const;
  double NaturalFrequencyHz() const;
  double DampingNmsPerRad() const;  // R_m
  // With the winding's R and L: the electrical impedance seen at the phase pair.
  MotionalImpedance Electrical(double r_ohm, double l_h) const;
};

// Stiffness that gives natural frequency f_hz with inertia J: k = J (2 pi f)^2.
double StiffnessForFrequency(double inertia_kg_m2, double f_hz);

}  // namespace eol::analysis
