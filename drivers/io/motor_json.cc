#include "drivers/io/motor_json.h"

#include <cmath>
#include <numbers>

#include "analysis/model/pmsm_network.h"
#include "drivers/io/json_config.h"

namespace eol::io {
namespace {

analysis::SpringDamper ReadSpring(const JsonObject& parent, const std::string& key,
                                  const analysis::SpringDamper& fallback) {
  const auto o = parent.OptionalObject(key);
  if (!o) return fallback;
  analysis::SpringDamper s;
  s.stiffness_nm_per_rad = o->Number("stiffness_nm_per_rad", fallback.stiffness_nm_per_rad);
  s.damping_nms_per_rad = o->Number("damping_nms_per_rad", fallback.damping_nms_per_rad);
  o->Require(s.stiffness_nm_per_rad > 0.0, "stiffness_nm_per_rad", "must be positive");
  o->Require(s.damping_nms_per_rad >= 0.0, "damping_nms_per_rad", "must not be negative");
  o->RejectUnknown();
  return s;
}

nlohmann::json SpringJson(const analysis::SpringDamper& s) {
  return {{"stiffness_nm_per_rad", s.stiffness_nm_per_rad},
          {"damping_nms_per_rad", s.damping_nms_per_rad}};
}

void ParseTransducer(const JsonObject& t, MotorSpec* m) {
  const bool direct = t.Has("transmission_nm_per_a");
  if (direct && (t.Has("t_hat_nm_per_a") || t.Has("poles") || t.Has("rotor_position_deg")))
    throw ConfigError(t.path() +
                      ": give either transmission_nm_per_a, or t_hat_nm_per_a with poles "
                      "(and rotor_position_deg), not both");
  if (direct) {
    m->transmission_nm_per_a = t.RequiredNumber("transmission_nm_per_a");
    t.Require(std::isfinite(*m->transmission_nm_per_a), "transmission_nm_per_a", "must be finite");
  } else {
    m->t_hat_nm_per_a = t.RequiredNumber("t_hat_nm_per_a");
    m->poles = t.Integer("poles", 0);
    t.Require(t.Has("poles"), "poles", "missing (required with t_hat_nm_per_a)");
    t.Require(m->poles >= 2 && m->poles % 2 == 0, "poles", "must be even and at least 2");
    t.Require(m->t_hat_nm_per_a > 0.0, "t_hat_nm_per_a", "must be positive");
    m->rotor_position_deg = t.Number("rotor_position_deg", 180.0 / m->poles);
  }
  t.RejectUnknown();
}

void ParseRotor(const JsonObject& r, int default_magnets, analysis::RotorChainParams* p) {
  p->magnets = r.Integer("magnets", default_magnets);
  r.Require(p->magnets >= 1 && p->magnets <= 200, "magnets", "must be in [1, 200]");
  p->magnet_inertia_kg_m2 = r.Number("magnet_inertia_kg_m2", p->magnet_inertia_kg_m2);
  p->pole_inertia_kg_m2 = r.Number("pole_inertia_kg_m2", p->pole_inertia_kg_m2);
  p->hub_inertia_kg_m2 = r.Number("hub_inertia_kg_m2", p->hub_inertia_kg_m2);
  r.Require(p->magnet_inertia_kg_m2 > 0.0, "magnet_inertia_kg_m2", "must be positive");
  r.Require(p->pole_inertia_kg_m2 > 0.0, "pole_inertia_kg_m2", "must be positive");
  r.Require(p->hub_inertia_kg_m2 > 0.0, "hub_inertia_kg_m2", "must be positive");
  p->bond = ReadSpring(r, "bond", p->bond);
  p->bond_poor = ReadSpring(r, "bond_poor", p->bond_poor);
  p->bridge = ReadSpring(r, "bridge", p->bridge);
  p->shaft = ReadSpring(r, "shaft", p->shaft);
  const std::vector<double> soft = r.Numbers("soft_magnets", {});
  p->soft_magnets.clear();
  for (std::size_t i = 0; i < soft.size(); ++i) {
    const std::string key = "soft_magnets/" + std::to_string(i);
    r.Require(soft[i] == std::floor(soft[i]) && soft[i] >= 0 && soft[i] < p->magnets, key,
              "must be a magnet index in [0, magnets)");
    p->soft_magnets.push_back(static_cast<int>(soft[i]));
  }
  std::string why;
  if (!p->IsValid(&why)) throw ConfigError(r.path() + ": " + why);
  r.RejectUnknown();
}

void ParseFixture(const JsonObject& root, analysis::RotorChainParams* p) {
  if (root.Has("fixture") && root.Raw("fixture").is_null()) {
    p->fixture.reset();
    return;
  }
  const auto f = root.OptionalObject("fixture");
  if (!f) return;  // the default fixture
  analysis::SpringDamper s = *p->fixture;
  s.stiffness_nm_per_rad = f->Number("stiffness_nm_per_rad", s.stiffness_nm_per_rad);
  s.damping_nms_per_rad = f->Number("damping_nms_per_rad", s.damping_nms_per_rad);
  p->clamp_inertia_kg_m2 = f->Number("clamp_inertia_kg_m2", p->clamp_inertia_kg_m2);
  f->Require(s.stiffness_nm_per_rad > 0.0, "stiffness_nm_per_rad",
             "must be positive (null for the whole fixture: rigid)");
  f->Require(s.damping_nms_per_rad >= 0.0, "damping_nms_per_rad", "must not be negative");
  f->Require(p->clamp_inertia_kg_m2 > 0.0, "clamp_inertia_kg_m2", "must be positive");
  f->RejectUnknown();
  p->fixture = s;
}

// "tolerances": each field optional over analysis::NominalTolerances' defaults.
analysis::NominalTolerances ParseTolerances(const JsonObject& o) {
  analysis::NominalTolerances t;
  for (const char* name : analysis::kToleranceNames)
    if (const auto v = o.OptionalNumber(name)) t.Set(name, *v);
  std::string why;
  if (!t.IsValid(&why)) throw ConfigError("/tolerances: " + why);
  o.RejectUnknown();
  return t;
}

}  // namespace

double MotorSpec::TransmissionNmPerA(std::optional<double> position_deg) const {
  if (transmission_nm_per_a) {
    if (position_deg)
      throw ConfigError("motor " + id +
                        ": a rotor position needs the transducer as t_hat_nm_per_a with poles "
                        "(the file gives transmission_nm_per_a)");
    return *transmission_nm_per_a;
  }
  const double deg = position_deg.value_or(rotor_position_deg);
  return analysis::TransmissionAtPosition(t_hat_nm_per_a, poles, deg * std::numbers::pi / 180.0);
}

analysis::ClampedMotor MotorSpec::Motor(std::optional<double> rotor_position_deg) const {
  return analysis::ClampedMotor{r_ohm, l_h, TransmissionNmPerA(rotor_position_deg),
                                analysis::BuildRotorChain(rotor)};
}

MotorSpec ParseMotorJson(const nlohmann::json& j, const std::string& source) {
  try {
    const JsonObject root(j, "");
    MotorSpec m;
    m.id = root.RequiredString("id");
    m.description = root.String("description", "");
    const JsonObject e = root.Object("electrical");
    m.r_ohm = e.RequiredNumber("r_ohm");
    m.l_h = e.RequiredNumber("l_h");
    e.Require(m.r_ohm > 0.0, "r_ohm", "must be positive");
    e.Require(m.l_h > 0.0, "l_h", "must be positive");
    e.RejectUnknown();
    ParseTransducer(root.Object("transducer"), &m);
    if (const auto r = root.OptionalObject("rotor"))
      ParseRotor(*r, m.poles > 0 ? m.poles : m.rotor.magnets, &m.rotor);
    else if (m.poles > 0)
      m.rotor.magnets = m.poles;
    ParseFixture(root, &m.rotor);
    if (root.Has("effects")) {
      m.effects = root.Raw("effects");
      if (!m.effects.is_array()) throw ConfigError(root.PathOf("effects") + ": must be an array");
    }
    if (const auto t = root.OptionalObject("tolerances")) m.tolerances = ParseTolerances(*t);
    root.RejectUnknown();
    return m;
  } catch (const ConfigError& e) {
    throw ConfigError("motor " + source + ": " + e.what());
  }
}

nlohmann::json ToleranceJson(const analysis::NominalTolerances& t) {
  return {{"r", t.r},
          {"l", t.l},
          {"torque_constant", t.torque_constant},
          {"inertia", t.inertia},
          {"stiffness", t.stiffness},
          {"damping", t.damping_factor},
          {"daq_gain", t.daq_gain}};
}

MotorSpec LoadMotorJson(const std::string& path) {
  return ParseMotorJson(io::ReadJsonFile(path), path);
}

namespace {
nlohmann::json ToJsonWithoutTolerances(const MotorSpec& m) {
  nlohmann::json transducer;
  if (m.transmission_nm_per_a)
    transducer = {{"transmission_nm_per_a", *m.transmission_nm_per_a}};
  else
    transducer = {{"t_hat_nm_per_a", m.t_hat_nm_per_a},
                  {"poles", m.poles},
                  {"rotor_position_deg", m.rotor_position_deg}};
  const analysis::RotorChainParams& r = m.rotor;
  nlohmann::json fixture = nullptr;
  if (r.fixture)
    fixture = {{"stiffness_nm_per_rad", r.fixture->stiffness_nm_per_rad},
               {"damping_nms_per_rad", r.fixture->damping_nms_per_rad},
               {"clamp_inertia_kg_m2", r.clamp_inertia_kg_m2}};
  return {{"id", m.id},
          {"description", m.description},
          {"electrical", {{"r_ohm", m.r_ohm}, {"l_h", m.l_h}}},
          {"transducer", transducer},
          {"rotor",
           {{"magnets", r.magnets},
            {"magnet_inertia_kg_m2", r.magnet_inertia_kg_m2},
            {"pole_inertia_kg_m2", r.pole_inertia_kg_m2},
            {"hub_inertia_kg_m2", r.hub_inertia_kg_m2},
            {"bond", SpringJson(r.bond)},
            {"bond_poor", SpringJson(r.bond_poor)},
            {"bridge", SpringJson(r.bridge)},
            {"shaft", SpringJson(r.shaft)},
            {"soft_magnets", r.soft_magnets}}},
          {"fixture", fixture},
          {"effects", m.effects}};
}

}  // namespace

nlohmann::json ToJson(const MotorSpec& m) {
  nlohmann::json j = ToJsonWithoutTolerances(m);
  if (m.tolerances) j["tolerances"] = ToleranceJson(*m.tolerances);
  return j;
}

}  // namespace eol::io
