// A production population of clamped ten-pole rotors, calibrated to the paper (analysis/README.md
// 2):
//   good rotor, rigid fixture            706 Hz  -> k_rotor = J (2 pi 706)^2
//   poorly cemented magnets, rigid       529 Hz  -> k_rotor_defect = J (2 pi 529)^2
//   good rotor in the default fixture    390 Hz  -> k_fixture from the series spring:
//       k_eff = J (2 pi 390)^2,  k_fixture = k_eff k_rotor / (k_rotor - k_eff)  (~0.44 k_rotor)
//   which puts the defective rotor at about 350 Hz in the default fixture.
// Units: kg m^2, N m/rad, N m/A, ohm, H. Spreads are relative standard deviations of a
// Gaussian, drawn independently per unit.
#pragma once

#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "analysis/model/motor_model.h"

namespace eol::analysis {

struct MotorPopulation {
  double inertia_kg_m2 = 1.0e-4;
  double f_rigid_hz = 706.0;
  double f_rigid_defect_hz = 529.0;
  double f_fixture_hz = 390.0;
  double q_good = 50.0;
  double q_defect = 35.0;  // a soft bond is also lossier
  double r_ohm = 0.5;
  double l_h = 2.0e-3;
  double transmission_nm_per_a = 0.05;

  double spread_inertia = 0.015;
  double spread_k_rotor = 0.03;
  double spread_k_fixture = 0.02;  // clamp force and fixture wear
  double spread_q = 0.10;
  double spread_r = 0.02;
  double spread_l = 0.02;
  double spread_transmission = 0.05;

  double defect_share = 0.1;  // probability that a drawn unit is poorly cemented
  std::uint64_t seed = 1;

  bool IsValid(std::string* why) const;
  double KRotorNmPerRad(bool defective) const;
  double KFixtureNmPerRad() const;
};

// The population's one field list: JSON key (the member's name) and member. The sim
// configuration's "population" object (drivers/factory ParsePopulation) and to_json /
// from_json below both walk it, so a field added here is read and written everywhere.
// "seed" (an integer) is the one field outside it.
struct PopulationNumber {
  const char* key;
  double MotorPopulation::*member;
};
inline constexpr std::array<PopulationNumber, 17> kPopulationNumbers = {{
    {"inertia_kg_m2", &MotorPopulation::inertia_kg_m2},
    {"f_rigid_hz", &MotorPopulation::f_rigid_hz},
    {"f_rigid_defect_hz", &MotorPopulation::f_rigid_defect_hz},
    {"f_fixture_hz", &MotorPopulation::f_fixture_hz},
    {"q_good", &MotorPopulation::q_good},
    {"q_defect", &MotorPopulation::q_defect},
    {"r_ohm", &MotorPopulation::r_ohm},
    {"l_h", &MotorPopulation::l_h},
    {"transmission_nm_per_a", &MotorPopulation::transmission_nm_per_a},
    {"spread_inertia", &MotorPopulation::spread_inertia},
    {"spread_k_rotor", &MotorPopulation::spread_k_rotor},
    {"spread_k_fixture", &MotorPopulation::spread_k_fixture},
    {"spread_q", &MotorPopulation::spread_q},
    {"spread_r", &MotorPopulation::spread_r},
    {"spread_l", &MotorPopulation::spread_l},
    {"spread_transmission", &MotorPopulation::spread_transmission},
    {"defect_share", &MotorPopulation::defect_share},
}};

// Every field; absent keys keep their defaults on reading. from_json does not validate
// (callers check IsValid and name their JSON path).
void to_json(nlohmann::json& j, const MotorPopulation& p);
void from_json(const nlohmann::json& j, MotorPopulation& p);

// One simulated unit: the truth the simulator knows and the station must find.
struct SimUnit {
  std::string serial;
  bool defective = false;
  ClampedRotor rotor;
  double r_ohm = 0.0;
  double l_h = 0.0;

  MotionalImpedance Electrical() const { return rotor.Electrical(r_ohm, l_h); }
};

// Deterministic in (population.seed, serial): the same serial is always the same unit.
SimUnit DrawUnit(const MotorPopulation& population, const std::string& serial);
// The same, with the defect forced.
SimUnit DrawUnit(const MotorPopulation& population, const std::string& serial, bool defective);

}  // namespace eol::analysis
