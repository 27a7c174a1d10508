// The station's configuration: one JSON file (deploy/station.json is the default).
//
// {
//   "station_id": "eol-1",
//   "recipe": "../recipes/pmsm-10pole.json",     relative paths are relative to this file
//   "db": "/var/lib/eol/eol.sqlite",
//   "http": {"listen": "127.0.0.1", "port": 8080,
//            "tokens": [{"name": "line1-operator", "role": "operator", "token": "..."},
//                       {"name": "qe-anna", "role": "engineer", "token": "..."}]},
//     Reads need no token. With tokens configured, starting a test needs an operator or
//     engineer token; changing the recipe always needs an engineer token.
//   "fixture": {"driver": "sim" | ...},              see drivers/factory/factory.h
//   "daq": {"driver": "sim" | ...},
//   "sim": {...},                                    the simulated bench, when a driver is sim
//   "safety": {"watchdog_period_ms": 5, "heartbeat_timeout_ms": 1500},
//   "serial_from_stdin": false,                      a scanner typing serials into stdin
//   "self_check": {"good_master": "MASTER-G", "limit_master": "MASTER-L",
//                  "every_n_tests": 50, "every_hours": 8}       optional, station/self_check.h
// }
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace eol::station {

struct SafetyOptions {
  double watchdog_period_ms = 5.0;     // interlock poll period during excitation
  double heartbeat_timeout_ms = 1500;  // controller heartbeat must change within this
  double poll_period_ms = 10.0;        // clamp/release confirmation polling
};

// What a token may do. Operators start tests; engineers also change and teach recipes.
// Ordered: a higher role may do everything a lower one may.
enum class Role { kOperator, kEngineer };

// "operator" or "engineer", as in the config and the audit log.
const char* ToString(Role role);
// The role named `text`, or nullopt when it names none.
std::optional<Role> ParseRole(std::string_view text);

struct ApiToken {
  std::string name;  // who, in the audit log
  Role role = Role::kOperator;
  std::string token;
};

// Self-checks with master parts (station/self_check.h). Off when good_master is empty.
struct SelfCheckConfig {
  std::string good_master;  // serial of a known good unit: must PASS
  std::string
      limit_master;        // serial of a deliberately soft-bonded rotor: must FAIL on the resonance
  int every_n_tests = 50;  // production tests a passing check covers (0: no count limit)
  double every_hours = 8.0;  // hours a passing check stays valid (0: no time limit)
  bool enabled() const { return !good_master.empty(); }
};

struct StationConfig {
  std::string station_id = "eol-1";
  std::string recipe_path;
  std::string db_path;
  std::string http_listen = "127.0.0.1";
  int http_port = 8080;
  std::vector<ApiToken> tokens;
  SafetyOptions safety;
  bool serial_from_stdin = false;
  SelfCheckConfig self_check;
  nlohmann::json drivers = nlohmann::json::object();  // {"fixture", "daq", "sim"}
};

// Throws io::ConfigError naming the file and the JSON path.
StationConfig ParseStationConfig(const nlohmann::json& j, const std::string& source,
                                 const std::string& base_dir);
StationConfig LoadStationConfig(const std::string& path);

}  // namespace eol::station
