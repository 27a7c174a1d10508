#include "analysis/model/motor_model.h"

#include <cmath>
#include <numbers>

namespace eol::analysis {

std::complex<double> MotionalImpedance::At(double f_hz) const {
  const std::complex<double> s(0.0, 2.0 * std::numbers::pi * f_hz);
  const double w0 = 2.0 * std::numbers::pi * f0_hz;
  const std::complex<double> zp = rp_ohm / (1.0 + q * (s / w0 + w0 / s));
  return r_ohm + s * l_h + zp;
}

Frf MotionalImpedance::Evaluate(const std::vector<double>& freq_hz) const {
  Frf z;
  z.freq_hz = freq_hz;
  z.value.reserve(freq_hz.size());
  for (double f : freq_hz) z.value.push_back(At(f));
  z.quantity = Quantity::kImpedanceOhm;
  z.method = "model";
  return z;
}

double MotionalImpedance::ResidueOhmPerS() const {
  return rp_ohm * 2.0 * std::numbers::pi * f0_hz / q;
}

double ClampedRotor::EffectiveStiffnessNmPerRad() const {
  if (std::isinf(k_fixture_nm_per_rad)) return k_rotor_nm_per_rad;
  return k_rotor_nm_per_rad * k_fixture_nm_per_rad / (k_rotor_nm_per_rad + k_fixture_nm_per_rad);
}

double ClampedRotor::NaturalFrequencyHz() const {
  return std::sqrt(EffectiveStiffnessNmPerRad() / inertia_kg_m2) / (2.0 * std::numbers::pi);
}

double ClampedRotor::DampingNmsPerRad() const {
  return std::sqrt(inertia_kg_m2 * EffectiveStiffnessNmPerRad()) / q;
}

MotionalImpedance ClampedRotor::Electrical(double r_ohm, double l_h) const {
  MotionalImpedance z;
  z.r_ohm = r_ohm;
  z.l_h = l_h;
  z.rp_ohm = transmission_nm_per_a * transmission_nm_per_a / DampingNmsPerRad();
  z.f0_hz = NaturalFrequencyHz();
  z.q = q;
  return z;
}

double StiffnessForFrequency(double inertia_kg_m2, double f_hz) {
  const double w = 2.0 * std::numbers::pi * f_hz;
  return inertia_kg_m2 * w * w;
}

}  // namespace eol::analysis
