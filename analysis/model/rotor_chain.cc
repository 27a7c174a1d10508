#include "analysis/model/rotor_chain.h"

#include <charconv>
#include <cmath>
#include <set>
#include <stdexcept>

namespace eol::analysis {
namespace {

bool Positive(double v) { return std::isfinite(v) && v > 0.0; }
bool SpringOk(const SpringDamper& s) {
  return Positive(s.stiffness_nm_per_rad) && std::isfinite(s.damping_nms_per_rad) &&
         s.damping_nms_per_rad >= 0.0;
}

}  // namespace

bool RotorChainParams::IsValid(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (magnets < 1) return fail("magnets must be at least 1");
  if (!Positive(magnet_inertia_kg_m2)) return fail("magnet_inertia_kg_m2 must be positive");
  if (!Positive(pole_inertia_kg_m2)) return fail("pole_inertia_kg_m2 must be positive");
  if (!Positive(hub_inertia_kg_m2)) return fail("hub_inertia_kg_m2 must be positive");
  if (!SpringOk(bond)) return fail("bond: stiffness must be positive, damping not negative");
  if (!SpringOk(bond_poor))
    return fail("bond_poor: stiffness must be positive, damping not negative");
  if (!SpringOk(bridge)) return fail("bridge: stiffness must be positive, damping not negative");
  if (!SpringOk(shaft)) return fail("shaft: stiffness must be positive, damping not negative");
  if (fixture) {
    if (!SpringOk(*fixture))
      return fail("fixture: stiffness must be positive, damping not negative");
    if (!Positive(clamp_inertia_kg_m2)) return fail("clamp_inertia_kg_m2 must be positive");
  }
  std::set<int> seen;
  for (int i : soft_magnets) {
    if (i < 0 || i >= magnets)
      return fail("soft magnet " + std::to_string(i) + " is not in [0, " + std::to_string(magnets) +
                  ")");
    if (!seen.insert(i).second) return fail("soft magnet " + std::to_string(i) + " is repeated");
  }
  return true;
}

TorsionalChain BuildRotorChain(const RotorChainParams& p) {
  std::string why;
  if (!p.IsValid(&why)) throw std::invalid_argument("rotor chain: " + why);
  const std::set<int> soft(p.soft_magnets.begin(), p.soft_magnets.end());
  TorsionalChain chain;
  std::vector<int> magnet, pole;
  for (int i = 0; i < p.magnets; ++i)
    magnet.push_back(chain.AddInertia("magnet_" + std::to_string(i), p.magnet_inertia_kg_m2));
  for (int i = 0; i < p.magnets; ++i)
    pole.push_back(chain.AddInertia("pole_" + std::to_string(i), p.pole_inertia_kg_m2));
  const int hub = chain.AddInertia("hub", p.hub_inertia_kg_m2);
  for (int i = 0; i < p.magnets; ++i) {
    const SpringDamper& b = soft.count(i) ? p.bond_poor : p.bond;
    const auto idx = static_cast<std::size_t>(i);
    chain.AddElement("bond_" + std::to_string(i), magnet[idx], pole[idx], b.stiffness_nm_per_rad,
                     b.damping_nms_per_rad);
    chain.AddElement("bridge_" + std::to_string(i), pole[idx], hub, p.bridge.stiffness_nm_per_rad,
                     p.bridge.damping_nms_per_rad);
    chain.SetTorqueWeight(magnet[idx], 1.0 / p.magnets);
  }
  if (p.fixture) {
    const int clamp = chain.AddInertia("clamp", p.clamp_inertia_kg_m2);
    chain.AddElement("shaft", hub, clamp, p.shaft.stiffness_nm_per_rad,
                     p.shaft.damping_nms_per_rad);
    chain.AddElement("fixture", clamp, kGround, p.fixture->stiffness_nm_per_rad,
                     p.fixture->damping_nms_per_rad);
  } else {
    chain.AddElement("shaft", hub, kGround, p.shaft.stiffness_nm_per_rad,
                     p.shaft.damping_nms_per_rad);
  }
  return chain;
}

bool SoftMagnetsForDefect(const std::string& defect, int magnets, std::vector<int>* soft,
                          std::string* why) {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  soft->clear();
  int count = 0;
  if (defect == "none") {
    count = 0;
  } else if (defect == "one_soft_magnet") {
    count = 1;
  } else if (defect == "all_soft") {
    count = magnets;
  } else if (defect.rfind("partial:", 0) == 0) {
    const std::string text = defect.substr(8);
    double ratio = -1.0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), ratio);
    if (ec != std::errc() || end != text.data() + text.size() || !(ratio >= 0.0 && ratio <= 1.0))
      return fail("defect '" + defect + "': the ratio after 'partial:' must be a number in [0, 1]");
    count = static_cast<int>(std::lround(ratio * magnets));
  } else {
    return fail("unknown defect '" + defect +
                "' (known: none, one_soft_magnet, all_soft, partial:<ratio>)");
  }
  for (int i = 0; i < count; ++i) soft->push_back(i);
  return true;
}

}  // namespace eol::analysis
