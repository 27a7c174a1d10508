// The one place that lists the drivers and makes them from configuration (drivers/README.md).
//
//   "fixture": {"driver": "sim"}                    in-process simulated bench
//   "fixture": {"driver": "modbus-tcp", "host": "10.0.0.20", "port": 502, "unit_id": 1, ...}
//   "fixture": {"driver": "modbus-rtu", "device": "/dev/ttyUSB0", "baud": 19200, ...}
//                                                   a Modbus controller (modbus_fixture.h;
//                                                   `eol fixture-sim` emulates one)
//   "daq":     {"driver": "sim", "model": "steady_state" | "time_domain",
//               "amplifier_output_ohm": 0, "time_scale": 0, "voltage_noise_v": 0.002, ...}
//                                                   the simulated acquisition (sim_daq.h)
//   "daq":     {"driver": "alsa", "playback": "default", "capture": "default", ...}
//                                                   a sound interface (alsa_daq.h)
//   "daq":     {"driver": "replay", "files": [...] | "directory": "..." | "file": "..."}
//                                                   recordings from files (replay_daq.h)
//              keys of these and the calibration: factory/daq_config.h
//   "sim":     {"population": {...}, "clamp_close_s": 0.15, ...,   the simulated bench
//               "masters": [{"serial": "MASTER-G"}, {"serial": "MASTER-L", "defective": true}],
//               "fixture_wear_per_test": 0.001,
//               "clamp_pressure_spread_bar": 0.3, "fixture_pressure_exponent": 0.333,
//               "alive_timeout_ms": 250}                          (sim_bench.h; 0 turns the
//                                                   controller's station-alive rule off)
//
// A simulator is chosen exactly as real hardware is. A driver that was not compiled in, or
// an unknown name, fails with a io::ConfigError naming the path and the known drivers.
#pragma once

#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "drivers/daq/daq.h"
#include "drivers/daq/replay_daq.h"
#include "drivers/fixture/fixture.h"
#include "drivers/io/json_config.h"
#include "drivers/sim/sim_bench.h"
#include "drivers/sim/sim_daq.h"

namespace eol::drivers {

struct DriverSet {
  std::unique_ptr<Fixture> fixture;
  std::unique_ptr<Daq> daq;
  // Called with each serial before its test; set only when a driver is simulated and the
  // simulated operator loads a part per serial (sim_bench.h load_part_on_serial). The
  // simulated drivers and this keep the bench alive.
  std::function<void(const std::string&)> on_serial;
};

// `station_config` is the whole station config; its "fixture", "daq" and optional "sim"
// objects are read. Throws io::ConfigError. Built without the simulators
// (eol::driver_factory_hardware, the daemon's program) a "sim" driver is such an error.
DriverSet MakeDrivers(const nlohmann::json& station_config);
// The same with a given `bench` used by the sim drivers instead of a new one: the demo shares
// one bench between the sim DAQ and the Modbus fixture emulator. Only in eol::driver_factory
// (with the simulators), as are the Parse* functions below.
DriverSet MakeDrivers(const nlohmann::json& station_config, std::shared_ptr<SimBench> bench);

SimBenchSettings ParseSimBenchSettings(const io::JsonObject& sim);
analysis::MotorPopulation ParsePopulation(const io::JsonObject& population);
SimDaqSettings ParseSimDaqSettings(const io::JsonObject& daq);

}  // namespace eol::drivers
