#include "analysis/sim/population.h"

#include <cmath>
#include <random>

namespace eol::analysis {
namespace {

// FNV-1a: a stable hash of the serial (std::hash may differ between library versions).
std::uint64_t Fnv1a(const std::string& s) {
  std::uint64_t h = 1469598103934665603ULL;
  for (unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ULL;
  }
  return h;
}

struct Draw {
  std::mt19937_64 rng;
  std::normal_distribution<double> normal{0.0, 1.0};
  std::uniform_real_distribution<double> uniform{0.0, 1.0};
  double Scale(double spread) { return std::max(0.05, 1.0 + spread * normal(rng)); }
};

}  // namespace

bool MotorPopulation::IsValid(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (!(inertia_kg_m2 > 0.0)) return fail("inertia_kg_m2 must be positive");
  if (!(f_rigid_hz > 0.0)) return fail("f_rigid_hz must be positive");
  if (!(f_rigid_defect_hz > 0.0 && f_rigid_defect_hz < f_rigid_hz))
    return fail("f_rigid_defect_hz must be positive and below f_rigid_hz");
  if (!(f_fixture_hz > 0.0 && f_fixture_hz < f_rigid_hz))
    return fail(
        "f_fixture_hz must be positive and below f_rigid_hz (the fixture is a spring in series)");
  if (!(q_good > 0.5 && q_defect > 0.5)) return fail("q_good and q_defect must be above 0.5");
  if (!(r_ohm > 0.0 && l_h > 0.0)) return fail("r_ohm and l_h must be positive");
  if (!(transmission_nm_per_a > 0.0)) return fail("transmission_nm_per_a must be positive");
  for (double s : {spread_inertia, spread_k_rotor, spread_k_fixture, spread_q, spread_r, spread_l,
                   spread_transmission})
    if (!(s >= 0.0 && s < 0.3)) return fail("every spread must be in [0, 0.3)");
  if (!(defect_share >= 0.0 && defect_share <= 1.0)) return fail("defect_share must be in [0, 1]");
  return true;
}

double MotorPopulation::KRotorNmPerRad(bool defective) const {
  return StiffnessForFrequency(inertia_kg_m2, defective ? f_rigid_defect_hz : f_rigid_hz);
}

double MotorPopulation::KFixtureNmPerRad() const {
  const double k_rotor = KRotorNmPerRad(false);
  const double k_eff = StiffnessForFrequency(inertia_kg_m2, f_fixture_hz);
  return k_eff * k_rotor / (k_rotor - k_eff);
}

SimUnit DrawUnit(const MotorPopulation& p, const std::string& serial) {
  std::mt19937_64 rng(Fnv1a(serial) ^ (p.seed * 0x9E3779B97F4A7C15ULL));
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  return DrawUnit(p, serial, uniform(rng) < p.defect_share);
}

SimUnit DrawUnit(const MotorPopulation& p, const std::string& serial, bool defective) {
  Draw d{std::mt19937_64(Fnv1a(serial) ^ (p.seed * 0xD1B54A32D192ED03ULL) ^ 0x5851F42D4C957F2DULL)};
  SimUnit u;
  u.serial = serial;
  u.defective = defective;
  u.rotor.inertia_kg_m2 = p.inertia_kg_m2 * d.Scale(p.spread_inertia);
  u.rotor.k_rotor_nm_per_rad = p.KRotorNmPerRad(defective) * d.Scale(p.spread_k_rotor);
  u.rotor.k_fixture_nm_per_rad = p.KFixtureNmPerRad() * d.Scale(p.spread_k_fixture);
  u.rotor.q = (defective ? p.q_defect : p.q_good) * d.Scale(p.spread_q);
  u.rotor.transmission_nm_per_a = p.transmission_nm_per_a * d.Scale(p.spread_transmission);
  u.r_ohm = p.r_ohm * d.Scale(p.spread_r);
  u.l_h = p.l_h * d.Scale(p.spread_l);
  return u;
}

void to_json(nlohmann::json& j, const MotorPopulation& p) {
  j = nlohmann::json::object();
  for (const PopulationNumber& f : kPopulationNumbers) j[f.key] = p.*f.member;
  j["seed"] = p.seed;
}

void from_json(const nlohmann::json& j, MotorPopulation& p) {
  p = MotorPopulation{};
  for (const PopulationNumber& f : kPopulationNumbers) p.*f.member = j.value(f.key, p.*f.member);
  p.seed = j.value("seed", p.seed);
}

}  // namespace eol::analysis
