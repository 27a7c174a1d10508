// A simulated motor described in JSON (recipes/motors/*.json), the input of `eol simulate`.
//
// {
//   "id": "pmsm-10pole", "description": "...",
//   "electrical": {"r_ohm": 0.5, "l_h": 0.002},                              required
//   "transducer": {"t_hat_nm_per_a": 0.05, "poles": 10, "rotor_position_deg": 18},  required,
//                 or {"transmission_nm_per_a": 0.05}: T at the clamped position directly
//   "rotor": {                                                     optional, defaults below
//     "magnets": 10,                        one magnet and one pole per pole of the machine
//     "magnet_inertia_kg_m2": 2.5e-6, "pole_inertia_kg_m2": 6.5e-6,
//     "hub_inertia_kg_m2": 1.0e-5,
//     "bond":      {"stiffness_nm_per_rad": 888.3, "damping_nms_per_rad": 3.338e-3},
//     "bond_poor": {"stiffness_nm_per_rad": 36.83, "damping_nms_per_rad": 4.151e-4},
//     "bridge":    {"stiffness_nm_per_rad": 370.1, "damping_nms_per_rad": 1.391e-3},
//     "shaft":     {"stiffness_nm_per_rad": 3701,  "damping_nms_per_rad": 1.391e-2},
//     "soft_magnets": []                    indices of the magnets with the poor bond
//   },
//   "fixture": {"stiffness_nm_per_rad": 887.9, "damping_nms_per_rad": 8.052e-3,
//               "clamp_inertia_kg_m2": 5e-6},           optional (default as shown);
//              null: a rigid fixture (the shaft end is ground)
//   "effects": [ ... ],                     optional, unmodelled effects: kept as raw JSON here
//                                           (analysis/model/effects.h reads them)
//   "tolerances": {"r": 0.10, "l": 0.08, "torque_constant": 0.06, "inertia": 0.06,
//                  "stiffness": 0.15, "damping": 3, "daq_gain": 0.01}
//                                           optional, each field optional (defaults shown):
//                                           the design's tolerances, one sd of each relative
//                                           offset (damping: a factor, log-normal), the prior
//                                           `eol gap` calibrates the nominal under
//                                           (analysis/gap/tolerance.h; --tolerances overrides)
// }
// The chain these numbers build is analysis/model/rotor_chain.h (the defaults are its
// ten-pole calibration: 706 Hz rigid, 529 Hz with every bond poor, 390 Hz in the default
// fixture). T(phi) = t_hat sin(p phi), p = poles / 2, phi = rotor_position_deg (default
// 90 / p: full coupling). rotor.magnets defaults to transducer.poles when that is given.
// Units are in the names. Unknown fields are errors. Every error is a io::ConfigError
// "motor <source>: <json path>: <rule>".
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "analysis/gap/tolerance.h"
#include "analysis/model/rotor_chain.h"
#include "analysis/model/torsional_chain.h"

namespace eol::io {

struct MotorSpec {
  std::string id;
  std::string description;
  double r_ohm = 0.0;
  double l_h = 0.0;
  // Transducer: either T directly, or T_hat with the pole count and rotor position.
  std::optional<double> transmission_nm_per_a;
  double t_hat_nm_per_a = 0.0;
  int poles = 0;
  double rotor_position_deg = 0.0;
  analysis::RotorChainParams rotor;  // fixture (nullopt: rigid) and soft magnets included
  nlohmann::json effects = nlohmann::json::array();
  std::optional<analysis::NominalTolerances> tolerances;  // "tolerances" when given

  // T at the file's rotor position, or at `rotor_position_deg` when given (which needs the
  // t_hat form; throws io::ConfigError naming the motor otherwise).
  double TransmissionNmPerA(std::optional<double> rotor_position_deg = std::nullopt) const;
  // The clamped motor (analysis/model/torsional_chain.h) at that rotor position.
  analysis::ClampedMotor Motor(std::optional<double> rotor_position_deg = std::nullopt) const;
};

// Throws io::ConfigError "motor <source>: <json path>: <rule>".
MotorSpec ParseMotorJson(const nlohmann::json& j, const std::string& source);
MotorSpec LoadMotorJson(const std::string& path);
// The "tolerances" object of a motor JSON.
nlohmann::json ToleranceJson(const analysis::NominalTolerances& t);
// The canonical JSON of a spec (every field written); ParseMotorJson(ToJson(s)) == s.
nlohmann::json ToJson(const MotorSpec& spec);

}  // namespace eol::io
