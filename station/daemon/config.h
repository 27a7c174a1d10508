// The station's configuration: one JSON file (deploy/station.json is the default).
//
// {
//   "station_id": "eol-1",
//   "recipe": "../recipes/pmsm-10pole.json",     relative paths are relative to this file
//   "variants": [{"name": "P10", "recipe": "...", "plc_code": 1, "prefixes": ["P10-"],
//                 "patterns": ["..."]}, ...]     instead of "recipe": several approved recipes,
//                                                one picked per unit (station/daemon/variants.h)
//   "db": "/var/lib/eol/eol.sqlite",
//   "http": {"listen": "127.0.0.1", "port": 8080,
//            "tokens": [{"name": "line1-operator", "role": "operator", "token": "..."},
//                       {"name": "qe-anna", "role": "engineer", "token": "..."}]},
//     Reads need no token. With tokens configured, starting a test needs an operator or
//     engineer token; changing the recipe always needs an engineer token. Listening beyond
//     loopback (anything but 127.0.0.0/8, ::1, localhost) needs tokens: refused otherwise.
//     "hosts": ["eol-1.plant.local"]: the names browsers reach the station by; a request
//     whose Host header is none of these, the listen address, the address it connected to
//     or a loopback name (localhost, 127.0.0.1, [::1]) is refused 421 (DNS rebinding).
//   "fixture": {"driver": "sim" | ...},              see drivers/factory/factory.h
//   "daq": {"driver": "sim" | ...},
//   "sim": {...},                                    the simulated bench, when a driver is sim
//   "safety": {"watchdog_period_ms": 5, "heartbeat_timeout_ms": 1500, "poll_period_ms": 10,
//              "safe_state_retry_s": 3, "watchdog_reaction_ms": 0, "alive_period_ms": 50},
//   "health": {"period_ms": 500},                  the idle look at the fixture controller and
//                                                    the DAQ while no test runs
//                                                    (station/daemon/health.h): "ready" follows a
//                                                    loss or a return within one period (plus one
//                                                    failed read)
//   "language": "en" | "de" | "ja",                the operator page's language (its
//                                                    catalogue station/web/i18n/<code>.json);
//                                                    the engineer switches a page with ?lang=
//   "serial_from_stdin": false,                      a scanner typing serials into stdin
//                                                    (its line format:
//                                                    station/daemon/test_request.h)
//   "self_check": {"good_master": "MASTER-G", "limit_master": "MASTER-L",
//                  "every_n_tests": 50, "every_hours": 8}       optional,
//                  station/daemon/self_check.h
//   "plc": {"listen": "127.0.0.1", "port": 502, "unit_id": 1, "max_clients": 8,
//           "frame_deadline_ms": 1000, "idle_timeout_s": 60,
//           "map": {"serial": 100, ...}}         optional: the line PLC's handshake, served
//                                                when the block is there (station/daemon/plc/).
//                                                "listen" defaults to loopback (Modbus has no
//                                                authentication): set it to the station's
//                                                address in the PLC network
//   "mqtt": {"url": "mqtt://host:1883" | "mqtts://host:8883", "topic_prefix": "plant/eol",
//            "client_id": "", "username": "", "password": "", "keepalive_s": 30,
//            "reconnect_s": 1,
//            "tls": {"ca_file": "ca.crt", "cert_file": "", "key_file": "", "insecure": false}}
//                                                optional: results and status to the MES
//                                                (station/daemon/mqtt_publisher.h); "tls" only with
//                                                mqtts:// (without it: the system's CAs);
//                                                each named file must be readable
//   "central": {"postgres": "postgresql://eol@db.plant:5432/plant", "batch": 200,
//               "retry_min_s": 0.5, "retry_max_s": 30, "connect_timeout_s": 5}
//                                                optional: every stored record into the
//                                                plant's PostgreSQL (station/daemon/central/)
// }
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "station/daemon/central/central_replicator.h"
#include "station/daemon/mqtt_publisher.h"
#include "station/daemon/plc/plc_server.h"
#include "station/daemon/variants.h"

namespace eol::station {

struct SafetyOptions {
  double watchdog_period_ms = 5.0;     // interlock poll period during excitation
  double heartbeat_timeout_ms = 1500;  // controller heartbeat must change within this
  double poll_period_ms = 10.0;        // clamp/release confirmation polling
  double safe_state_retry_s = 3.0;     // on a fault, excitation off and unclamp retried this long
  // Longest gap between two successful interlock reads during excitation before the
  // watchdog calls it a stall (ERROR); 0: 4 x watchdog_period_ms, at least 100 ms.
  double watchdog_reaction_ms = 0.0;
  // station_alive is written this often during excitation; the controller drops the relay
  // 250 ms after the last change (drivers/fixture/modbus_map.h).
  double alive_period_ms = 50.0;
};

// The station's live health (station/daemon/health.h).
struct HealthOptions {
  double period_ms = 500.0;  // idle look at the fixture controller and the DAQ; 50..10000
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

// Self-checks with master parts (station/daemon/self_check.h). Off when good_master is empty.
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
  // The one recipe; with variants, the first variant's (shown until the first unit).
  std::string recipe_path;
  // Several recipes, one picked per unit (station/daemon/variants.h); empty: the one recipe.
  std::vector<VariantConfig> variants;
  std::string db_path;
  // Make an existing empty file at db_path a new store (db::OpenOptions::create_if_empty;
  // config "init_store", `--init-store`). Without it such a file is refused; a missing file
  // is always created.
  bool init_store = false;
  std::string http_listen = "127.0.0.1";
  int http_port = 8080;
  std::vector<ApiToken> tokens;
  // Host header values the API answers besides the listen address and loopback names.
  std::vector<std::string> http_hosts;
  SafetyOptions safety;
  HealthOptions health;
  bool serial_from_stdin = false;
  std::string language =
      "en";  // the operator page's (kPageLanguages, station/daemon/reason_cause.h)
  // Store and publish the verdict while the clamp opens (SequencerOptions,
  // station/daemon/sequencer.h).
  bool publish_before_release = false;
  SelfCheckConfig self_check;
  nlohmann::json drivers = nlohmann::json::object();  // {"fixture", "daq", "sim"}
  // Plant integration (issue 15): the line PLC's handshake; nullopt without a "plc" block.
  std::optional<plc::PlcServerSettings> plc;
  // Plant integration: results to the MES over MQTT; nullopt without an "mqtt" block.
  std::optional<MqttConfig> mqtt;
  // Plant integration: the central PostgreSQL record; nullopt without a "central" block.
  std::optional<central::CentralConfig> central;
};

// Non-empty when the station runs on simulators or recorded data rather than a real fixture
// and DAQ ("fixture driver 'sim'", "daq driver 'replay'"): its records are no production
// results, and the page and every record say SIMULATION.
std::string SimulationReason(const StationConfig& config);

// Throws io::ConfigError naming the file and the JSON path.
StationConfig ParseStationConfig(const nlohmann::json& j, const std::string& source,
                                 const std::string& base_dir);
StationConfig LoadStationConfig(const std::string& path);

}  // namespace eol::station
