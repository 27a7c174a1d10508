#include "drivers/factory/factory.h"

#include "drivers/daq/calibration_file.h"
#include "drivers/factory/daq_config.h"
#include "drivers/fixture/modbus_fixture.h"
#if EOL_FACTORY_WITH_SIM
#include "drivers/sim/sim_fixture.h"
#endif
#if EOL_WITH_SOCKETCAN
#include "drivers/fixture/can_fixture.h"
#endif

namespace eol::drivers {

#if EOL_FACTORY_WITH_SIM
analysis::MotorPopulation ParsePopulation(const io::JsonObject& o) {
  analysis::MotorPopulation p;
  for (const analysis::PopulationNumber& f : analysis::kPopulationNumbers)
    p.*f.member = o.Number(f.key, p.*f.member);
  p.seed = static_cast<std::uint64_t>(o.Integer("seed", static_cast<int>(p.seed)));
  o.RejectUnknown();
  std::string why;
  if (!p.IsValid(&why)) throw io::ConfigError(o.path() + ": " + why);
  return p;
}

SimBenchSettings ParseSimBenchSettings(const io::JsonObject& o) {
  SimBenchSettings s;
  if (auto pop = o.OptionalObject("population")) s.population = ParsePopulation(*pop);
  s.clamp_close_s = o.Number("clamp_close_s", s.clamp_close_s);
  s.clamp_open_s = o.Number("clamp_open_s", s.clamp_open_s);
  s.clamp_pressure_bar = o.Number("clamp_pressure_bar", s.clamp_pressure_bar);
  s.heartbeat_period_s = o.Number("heartbeat_period_s", s.heartbeat_period_s);
  s.load_part_on_serial = o.Bool("load_part_on_serial", s.load_part_on_serial);
  s.fixture_wear_per_test = o.Number("fixture_wear_per_test", s.fixture_wear_per_test);
  o.Require(s.fixture_wear_per_test >= 0 && s.fixture_wear_per_test <= 0.01,
            "fixture_wear_per_test", "must be in [0, 0.01] (share of the stiffness per part)");
  s.clamp_pressure_spread_bar = o.Number("clamp_pressure_spread_bar", s.clamp_pressure_spread_bar);
  o.Require(
      s.clamp_pressure_spread_bar >= 0 && s.clamp_pressure_spread_bar <= 0.1 * s.clamp_pressure_bar,
      "clamp_pressure_spread_bar", "must be in [0, 10 % of clamp_pressure_bar] (bar)");
  s.alive_timeout_ms = o.Number("alive_timeout_ms", s.alive_timeout_ms);
  o.Require(
      s.alive_timeout_ms == 0 || (s.alive_timeout_ms >= 100 && s.alive_timeout_ms <= 1000),
      "alive_timeout_ms",
      "must be 0 (no station-alive rule) or in [100, 1000] ms (drivers/fixture/modbus_map.h)");
  s.fixture_pressure_exponent = o.Number("fixture_pressure_exponent", s.fixture_pressure_exponent);
  o.Require(s.fixture_pressure_exponent >= 0 && s.fixture_pressure_exponent <= 1,
            "fixture_pressure_exponent", "must be in [0, 1] (k_fixture ~ p^exponent)");
  if (o.Has("masters")) {
    const nlohmann::json& list = o.Raw("masters");
    if (!list.is_array()) throw io::ConfigError(o.PathOf("masters") + ": must be an array");
    for (std::size_t i = 0; i < list.size(); ++i) {
      const io::JsonObject m(list[i], o.PathOf("masters") + "/" + std::to_string(i));
      SimMaster master{m.RequiredString("serial"), m.Bool("defective", false)};
      m.Require(!master.serial.empty(), "serial", "must not be empty");
      m.RejectUnknown();
      s.masters.push_back(master);
    }
  }
  o.Require(s.clamp_close_s > 0 && s.clamp_close_s < 10, "clamp_close_s", "must be in (0, 10) s");
  o.Require(s.clamp_open_s > 0 && s.clamp_open_s < 10, "clamp_open_s", "must be in (0, 10) s");
  o.Require(s.heartbeat_period_s > 0 && s.heartbeat_period_s <= 0.5, "heartbeat_period_s",
            "must be in (0, 0.5] s");
  o.RejectUnknown();
  return s;
}

SimDaqSettings ParseSimDaqSettings(const io::JsonObject& o) {
  SimDaqSettings s;
  const std::string model = o.String("model", ToString(s.model));
  if (model == ToString(SimMotorModel::kSteadyState)) {
    s.model = SimMotorModel::kSteadyState;
  } else if (model == ToString(SimMotorModel::kTimeDomain)) {
    s.model = SimMotorModel::kTimeDomain;
  } else {
    o.Require(false, "model", "must be \"steady_state\" or \"time_domain\"");
  }
  s.amplifier_output_ohm = o.Number("amplifier_output_ohm", s.amplifier_output_ohm);
  o.Require(s.amplifier_output_ohm >= 0.0, "amplifier_output_ohm", "must not be negative");
  s.time_scale = o.Number("time_scale", s.time_scale);
  s.voltage_noise_v = o.Number("voltage_noise_v", s.voltage_noise_v);
  s.current_noise_a = o.Number("current_noise_a", s.current_noise_a);
  s.voltage_full_scale_v = o.Number("voltage_full_scale_v", s.voltage_full_scale_v);
  s.current_full_scale_a = o.Number("current_full_scale_a", s.current_full_scale_a);
  s.seed = static_cast<std::uint64_t>(o.Integer("seed", static_cast<int>(s.seed)));
  const std::string relay = o.String("relay", "bench");
  o.Require(relay == "bench" || relay == "external", "relay", "must be \"bench\" or \"external\"");
  s.relay_external = relay == "external";
  ParseSimCalibrationLoad(o, s);
  o.Require(s.time_scale >= 0.0, "time_scale", "must not be negative");
  o.Require(s.voltage_noise_v >= 0.0, "voltage_noise_v", "must not be negative");
  o.Require(s.current_noise_a >= 0.0, "current_noise_a", "must not be negative");
  o.Require(s.voltage_full_scale_v > 0.0, "voltage_full_scale_v", "must be positive");
  o.Require(s.current_full_scale_a > 0.0, "current_full_scale_a", "must be positive");
  o.RejectUnknown();
  return s;
}
#endif

namespace {

// The hardware fixture drivers; `driver` is none of them: an io::ConfigError.
std::unique_ptr<Fixture> HardwareFixture(const io::JsonObject& fixture, const std::string& driver) {
  if (driver == "modbus-tcp")
    return std::make_unique<ModbusFixture>(
        ParseModbusFixtureSettings(fixture, ModbusLink::Transport::kTcp));
  if (driver == "modbus-rtu")
    return std::make_unique<ModbusFixture>(
        ParseModbusFixtureSettings(fixture, ModbusLink::Transport::kRtu));
  if (driver == "socketcan") {
#if EOL_WITH_SOCKETCAN
    return std::make_unique<CanFixture>(ParseCanFixtureSettings(fixture));
#else
    throw io::ConfigError(fixture.PathOf("driver") +
                          ": the socketcan fixture driver was not compiled in (build with "
                          "-DEOL_WITH_SOCKETCAN=ON)");
#endif
  }
  throw io::ConfigError(fixture.PathOf("driver") + ": unknown fixture driver '" + driver +
                        "' (known: sim, modbus-tcp, modbus-rtu, socketcan)");
}

// The hardware and file acquisition drivers; `driver` is none of them: an io::ConfigError.
std::unique_ptr<Daq> HardwareDaq(const io::JsonObject& daq, const std::string& driver) {
  if (driver == "alsa") {
    const AlsaDaqSettings alsa = ParseAlsaDaqSettings(daq);
#if EOL_WITH_ALSA
    return std::make_unique<AlsaDaq>(alsa);
#else
    throw io::ConfigError(
        daq.PathOf("driver") +
        ": the alsa driver was not compiled in (configure with -DEOL_WITH_ALSA=ON)");
#endif
  }
  if (driver == "replay") return std::make_unique<ReplayDaq>(ParseReplayDaqSettings(daq));
  throw io::ConfigError(daq.PathOf("driver") + ": unknown daq driver '" + driver +
                        "' (known: sim, alsa, replay)");
}

}  // namespace

#if EOL_FACTORY_WITH_SIM
DriverSet MakeDrivers(const nlohmann::json& station_config) {
  return MakeDrivers(station_config, nullptr);
}

DriverSet MakeDrivers(const nlohmann::json& station_config, std::shared_ptr<SimBench> bench) {
  const io::JsonObject root(station_config, "");
  const io::JsonObject fixture = root.Object("fixture");
  const io::JsonObject daq = root.Object("daq");
  const std::string fixture_driver = fixture.RequiredString("driver");
  const std::string daq_driver = daq.RequiredString("driver");

  DriverSet set;
  if (bench) {
    (void)root.OptionalObject("sim");  // the caller built the bench from it
  } else if (fixture_driver == "sim" || daq_driver == "sim") {
    const auto sim = root.OptionalObject("sim");
    bench = std::make_shared<SimBench>(sim ? ParseSimBenchSettings(*sim) : SimBenchSettings{});
  }
  if (bench && bench->settings().load_part_on_serial)
    set.on_serial = [bench](const std::string& serial) { bench->LoadPart(serial); };
  if (fixture_driver == "sim") {
    fixture.RejectUnknown();
    set.fixture = std::make_unique<SimFixture>(bench);
  } else {
    set.fixture = HardwareFixture(fixture, fixture_driver);
  }
  set.daq = daq_driver == "sim" ? std::make_unique<SimDaq>(bench, ParseSimDaqSettings(daq))
                                : HardwareDaq(daq, daq_driver);
  return set;
}
#else
DriverSet MakeDrivers(const nlohmann::json& station_config) {
  const io::JsonObject root(station_config, "");
  const io::JsonObject fixture = root.Object("fixture");
  const io::JsonObject daq = root.Object("daq");
  const std::string fixture_driver = fixture.RequiredString("driver");
  const std::string daq_driver = daq.RequiredString("driver");
  // What a config naming a simulated driver is told by a program built without them.
  for (const io::JsonObject* o : {&fixture, &daq})
    if (o->RequiredString("driver") == "sim")
      throw io::ConfigError(o->PathOf("driver") +
                            ": the sim driver is not in this program (the daemon eol-station "
                            "has the hardware drivers only; `eol station` and `eol demo` run "
                            "a simulated station)");
  DriverSet set;
  set.fixture = HardwareFixture(fixture, fixture_driver);
  set.daq = HardwareDaq(daq, daq_driver);
  return set;
}
#endif

}  // namespace eol::drivers
