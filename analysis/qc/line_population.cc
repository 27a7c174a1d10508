#include "analysis/qc/line_population.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

namespace eol::analysis {
namespace {

constexpr double kCopperTempco = 0.00393;  // 1/K at 20 deg C

struct Rng {
  std::mt19937_64 gen;
  std::normal_distribution<double> normal{0.0, 1.0};
  std::uniform_real_distribution<double> uniform{0.0, 1.0};
  double Scale(double spread) { return std::max(0.05, 1.0 + spread * normal(gen)); }
  double Uniform(double lo, double hi) { return lo + (hi - lo) * uniform(gen); }
};

std::uint64_t Mix(std::uint64_t seed, std::uint64_t index, std::uint64_t salt) {
  std::uint64_t z = seed * 0x9E3779B97F4A7C15ULL ^ (index + 0x632BE59BD9B4E019ULL) * salt;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

int SoftCount(DefectClass c, int magnets) {
  switch (c) {
    case DefectClass::kOneSoftMagnet:
      return 1;
    case DefectClass::kTwoSoftMagnets:
      return std::min(2, magnets);
    case DefectClass::kHalfSoft:
      return magnets / 2;
    case DefectClass::kAllSoft:
      return magnets;
    default:
      return 0;
  }
}

}  // namespace

const char* ToString(DefectClass c) {
  switch (c) {
    case DefectClass::kGood:
      return "good";
    case DefectClass::kOneSoftMagnet:
      return "one_soft_magnet";
    case DefectClass::kTwoSoftMagnets:
      return "two_soft_magnets";
    case DefectClass::kHalfSoft:
      return "half_soft";
    case DefectClass::kAllSoft:
      return "all_soft";
    case DefectClass::kWeakBonds:
      return "weak_bonds";
  }
  return "good";
}

bool LineSpread::IsValid(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  for (double s :
       {magnet_inertia, bond_stiffness, bond_damping, bridge_stiffness, hub_inertia,
        shaft_stiffness, fixture_damping, fixture_wear, spread_r, spread_l, spread_transmission})
    if (!(s >= 0.0 && s < 0.3)) return fail("every relative spread must be in [0, 0.3)");
  if (!(clamp_pressure_lo_bar > 0.0 && clamp_pressure_hi_bar > clamp_pressure_lo_bar))
    return fail("clamp pressure window must be positive and increasing");
  if (!(clamp_pressure_sd_bar >= 0.0)) return fail("clamp_pressure_sd_bar must not be negative");
  if (!(r_ohm > 0.0 && l_h > 0.0 && transmission_nm_per_a > 0.0))
    return fail("r_ohm, l_h and transmission_nm_per_a must be positive");
  if (!(temperature_hi_c >= temperature_lo_c))
    return fail("temperature_hi_c below temperature_lo_c");
  if (!(weak_fraction_lo > 0.0 && weak_fraction_hi >= weak_fraction_lo && weak_fraction_hi <= 1.0))
    return fail("weak bond fractions must satisfy 0 < lo <= hi <= 1");
  return true;
}

double DefectRates::Total() const {
  return one_soft_magnet + two_soft_magnets + half_soft + all_soft + weak_bonds;
}

bool DefectRates::IsValid(std::string* why) const {
  for (double r : {one_soft_magnet, two_soft_magnets, half_soft, all_soft, weak_bonds})
    if (!(r >= 0.0 && r <= 1.0)) {
      if (why) *why = "every defect rate must be in [0, 1]";
      return false;
    }
  if (!(Total() <= 1.0)) {
    if (why) *why = "defect rates add up to more than 1";
    return false;
  }
  return true;
}

LineUnit DrawLineUnit(const RotorChainParams& nominal, const LineSpread& spread,
                      const DefectRates& rates, std::uint64_t seed, std::uint64_t index) {
  Rng pick{std::mt19937_64(Mix(seed, index, 0xA24BAED4963EE407ULL))};
  const double u = pick.uniform(pick.gen);
  const double edges[] = {rates.one_soft_magnet, rates.two_soft_magnets, rates.half_soft,
                          rates.all_soft, rates.weak_bonds};
  const DefectClass classes[] = {DefectClass::kOneSoftMagnet, DefectClass::kTwoSoftMagnets,
                                 DefectClass::kHalfSoft, DefectClass::kAllSoft,
                                 DefectClass::kWeakBonds};
  double acc = 0.0;
  DefectClass c = DefectClass::kGood;
  for (int i = 0; i < 5; ++i) {
    acc += edges[i];
    if (u < acc) {
      c = classes[i];
      break;
    }
  }
  return DrawLineUnit(nominal, spread, c, seed, index);
}

LineUnit DrawLineUnit(const RotorChainParams& p, const LineSpread& s, DefectClass defect,
                      std::uint64_t seed, std::uint64_t index) {
  Rng r{std::mt19937_64(Mix(seed, index, 0x9FB21C651E98DF25ULL))};
  LineUnit unit;
  unit.defect = defect;
  const int n = p.magnets;
  std::vector<int> order(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) order[static_cast<std::size_t>(i)] = i;
  std::shuffle(order.begin(), order.end(), r.gen);
  std::vector<bool> soft(static_cast<std::size_t>(n), false);
  for (int i = 0; i < SoftCount(defect, n); ++i)
    soft[static_cast<std::size_t>(order[static_cast<std::size_t>(i)])] = true;
  const double weak =
      defect == DefectClass::kWeakBonds ? r.Uniform(s.weak_fraction_lo, s.weak_fraction_hi) : 1.0;

  TorsionalChain& chain = unit.motor.chain;
  std::vector<int> magnet, pole;
  for (int i = 0; i < n; ++i)
    magnet.push_back(chain.AddInertia("magnet_" + std::to_string(i),
                                      p.magnet_inertia_kg_m2 * r.Scale(s.magnet_inertia)));
  for (int i = 0; i < n; ++i)
    pole.push_back(chain.AddInertia("pole_" + std::to_string(i), p.pole_inertia_kg_m2));
  const int hub = chain.AddInertia("hub", p.hub_inertia_kg_m2 * r.Scale(s.hub_inertia));
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const SpringDamper& b = soft[k] ? p.bond_poor : p.bond;
    chain.AddElement("bond_" + std::to_string(i), magnet[k], pole[k],
                     weak * b.stiffness_nm_per_rad * r.Scale(s.bond_stiffness),
                     weak * b.damping_nms_per_rad * r.Scale(s.bond_damping));
    chain.AddElement("bridge_" + std::to_string(i), pole[k], hub,
                     p.bridge.stiffness_nm_per_rad * r.Scale(s.bridge_stiffness),
                     p.bridge.damping_nms_per_rad);
    chain.SetTorqueWeight(magnet[k], 1.0 / n);
  }
  const double pressure =
      std::clamp(s.clamp_pressure_mean_bar + s.clamp_pressure_sd_bar * r.normal(r.gen),
                 s.clamp_pressure_lo_bar, s.clamp_pressure_hi_bar);
  unit.clamp_pressure_bar = pressure;
  const SpringDamper fixture = p.fixture.value_or(SpringDamper{});
  const int clamp = chain.AddInertia("clamp", p.clamp_inertia_kg_m2);
  chain.AddElement("shaft", hub, clamp, p.shaft.stiffness_nm_per_rad * r.Scale(s.shaft_stiffness),
                   p.shaft.damping_nms_per_rad);
  chain.AddElement("fixture", clamp, kGround,
                   fixture.stiffness_nm_per_rad * std::cbrt(pressure / s.clamp_pressure_mean_bar) *
                       r.Scale(s.fixture_wear),
                   fixture.damping_nms_per_rad * r.Scale(s.fixture_damping));

  unit.temperature_c = r.Uniform(s.temperature_lo_c, s.temperature_hi_c);
  unit.motor.r_ohm =
      s.r_ohm * r.Scale(s.spread_r) * (1.0 + kCopperTempco * (unit.temperature_c - 20.0));
  unit.motor.l_h = s.l_h * r.Scale(s.spread_l);
  unit.motor.transmission_nm_per_a = s.transmission_nm_per_a * r.Scale(s.spread_transmission);
  return unit;
}

RotorChainParams NominalWithDefect(const RotorChainParams& nominal, DefectClass defect,
                                   double bond_fraction) {
  RotorChainParams p = nominal;
  p.soft_magnets.clear();
  for (int i = 0; i < SoftCount(defect, p.magnets); ++i) p.soft_magnets.push_back(i);
  if (defect == DefectClass::kWeakBonds) {
    p.bond.stiffness_nm_per_rad *= bond_fraction;
    p.bond.damping_nms_per_rad *= bond_fraction;
  }
  return p;
}

std::vector<std::complex<double>> ModalImpedance(const ClampedMotor& motor,
                                                 const std::vector<double>& freq_hz) {
  const std::vector<ChainMode> modes = motor.chain.Modes();
  const double t2 = motor.transmission_nm_per_a * motor.transmission_nm_per_a;
  std::vector<std::complex<double>> z;
  z.reserve(freq_hz.size());
  for (double f : freq_hz) {
    const std::complex<double> s(0.0, 2.0 * std::numbers::pi * f);
    std::complex<double> v = motor.r_ohm + s * motor.l_h;
    for (const ChainMode& m : modes) {
      if (!(m.participation > 0.0)) continue;
      const double w = 2.0 * std::numbers::pi * m.f_hz;
      v += t2 * m.participation * s / (s * s + s * (w / m.q) + w * w);
    }
    z.push_back(v);
  }
  return z;
}

}  // namespace eol::analysis
