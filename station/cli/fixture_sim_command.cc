// `eol fixture-sim`: a fixture controller emulator. It builds a simulated bench and serves
// it as a Modbus TCP server (and, with --rtu, as a Modbus RTU server on a serial device)
// through the fixture signal map, so that the station's modbus-tcp/modbus-rtu drivers, or
// any Modbus tool, can be run without hardware; with --can IFNAME it also serves the bench
// as a CAN node (drivers::CanFixtureNode, frame map drivers/fixture/can_map.h) for the
// socketcan driver, can-utils or python-can. The servers are drivers::ModbusFixtureServer
// and drivers::CanFixtureNode; this file only wires options to them.
#include <signal.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "drivers/emulators/modbus_fixture_server.h"
#include "drivers/factory/factory.h"
#include "drivers/io/json_config.h"
#include "drivers/sim/sim_bench.h"
#if EOL_WITH_SOCKETCAN
#include "drivers/emulators/can_fixture_node.h"
#endif
#include "station/cli/commands.h"
#include "station/cli/common.h"

namespace eol::station::cli {
namespace {

struct FixtureSimOptions {
  std::string config;
  std::string listen = "127.0.0.1";
  int port = 1502;
  int unit_id = 1;
  std::string rtu_device;
  int baud = 19200;
  std::string parity = "E";
  int data_bits = 8;
  int stop_bits = 1;
  std::string part;
  bool load_part_on_clamp = false;
  std::string fault;
  int fault_after_ms = 0;
  int fault_duration_ms = 0;  // 0: until the emulator stops
  bool fault_on_excitation = false;
  std::string ready_file;
  std::string can_interface;
  int node_id = 0;  // 0: the config's fixture "node_id", else 1
  int status_period_ms = 50;
};

std::string FaultNames() {
  std::string names;
  for (drivers::SimFault f : drivers::kSimFaults)
    names += (names.empty() ? "" : ", ") + std::string(drivers::ToString(f));
  return names;
}

// Written to a temporary name and renamed, so a waiting test never reads half a file.
void WriteReadyFile(const std::string& path, int port) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << port << "\n";
    if (!out) throw std::runtime_error(tmp + ": cannot be written");
  }
  std::filesystem::rename(tmp, path);
}

int RunFixtureSim(const FixtureSimOptions& opt) {
  // The servers' threads inherit this mask, so SIGTERM/SIGINT reach sigwait() below only.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGTERM);
  sigaddset(&stop_signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);

  drivers::SimBenchSettings bench_settings;
  drivers::ModbusMap map;
  std::optional<io::JsonObject> can_fixture;  // a "socketcan" fixture object
  nlohmann::json config;
  if (!opt.config.empty()) {
    config = io::ReadJsonFile(opt.config);
    const io::JsonObject root(config, "");
    if (const auto sim = root.OptionalObject("sim"))
      bench_settings = drivers::ParseSimBenchSettings(*sim);
    // The station's own fixture map, so that one config file serves both ends.
    const auto fixture = root.OptionalObject("fixture");
    if (fixture && fixture->String("driver", "") == "socketcan") {
      can_fixture.emplace(*fixture);  // its frame map, for --can
    } else if (fixture && fixture->Has("map")) {
      map = drivers::ParseModbusMap(fixture->Raw("map"), fixture->PathOf("map"));
    }
  }
  auto bench = std::make_shared<drivers::SimBench>(bench_settings);
  if (!opt.part.empty()) bench->LoadPart(opt.part);
  if (!opt.fault.empty()) {
    const auto fault = drivers::ParseSimFault(opt.fault);
    if (!fault)
      throw std::runtime_error("--fault: unknown fault '" + opt.fault +
                               "' (known: " + FaultNames() + ")");
    std::optional<std::chrono::milliseconds> duration;
    if (opt.fault_duration_ms > 0) duration = std::chrono::milliseconds(opt.fault_duration_ms);
    bench->InjectFault(*fault, std::chrono::milliseconds(opt.fault_after_ms),
                       opt.fault_on_excitation, duration);
  }

  drivers::ModbusFixtureServerSettings tcp;
  tcp.link.transport = drivers::ModbusLink::Transport::kTcp;
  tcp.link.host = opt.listen;
  tcp.link.port = opt.port;
  tcp.link.unit_id = opt.unit_id;
  tcp.map = map;
  tcp.load_part_on_clamp = opt.load_part_on_clamp;
  drivers::ModbusFixtureServer tcp_server(bench, tcp);
  if (const drivers::Status s = tcp_server.Start(); !s.ok()) throw std::runtime_error(s.message());

  std::optional<drivers::ModbusFixtureServer> rtu_server;
  if (!opt.rtu_device.empty()) {
    drivers::ModbusFixtureServerSettings rtu = tcp;
    rtu.link.transport = drivers::ModbusLink::Transport::kRtu;
    rtu.link.device = opt.rtu_device;
    rtu.link.baud = opt.baud;
    rtu.link.parity = opt.parity.empty() ? '?' : opt.parity[0];
    rtu.link.data_bits = opt.data_bits;
    rtu.link.stop_bits = opt.stop_bits;
    rtu_server.emplace(bench, rtu);
    if (const drivers::Status s = rtu_server->Start(); !s.ok())
      throw std::runtime_error(s.message());
  }

#if EOL_WITH_SOCKETCAN
  std::optional<drivers::CanFixtureNode> can_node;
  if (!opt.can_interface.empty()) {
    drivers::CanFixtureNodeSettings can;
    can.interface = opt.can_interface;
    if (can_fixture) can.map = drivers::ParseCanFixtureSettings(*can_fixture).map;
    if (opt.node_id != 0) can.map.node_id = opt.node_id;
    can.status_period_ms = opt.status_period_ms;
    can.load_part_on_clamp = opt.load_part_on_clamp;
    can_node.emplace(bench, can);
    if (const drivers::Status s = can_node->Start(); !s.ok()) throw std::runtime_error(s.message());
  }
#else
  if (!opt.can_interface.empty())
    throw std::runtime_error(
        "--can: SocketCAN was not compiled in (build with "
        "-DEOL_WITH_SOCKETCAN=ON)");
#endif

  if (!opt.ready_file.empty()) WriteReadyFile(opt.ready_file, tcp_server.port());
  int sig = 0;
  sigwait(&stop_signals, &sig);
  spdlog::info("fixture-sim: {} received, stopping", sig == SIGTERM ? "SIGTERM" : "SIGINT");
#if EOL_WITH_SOCKETCAN
  if (can_node) can_node->Stop();
#endif
  if (rtu_server) rtu_server->Stop();
  tcp_server.Stop();
  return 0;
}

}  // namespace

void AddFixtureSimCommand(CLI::App& app) {
  auto opt = std::make_shared<FixtureSimOptions>();
  auto* cmd = app.add_subcommand(
      "fixture-sim",
      "Fixture controller emulator: serves a simulated bench over Modbus TCP (and RTU with\n"
      "--rtu) through the fixture signal map (drivers/fixture/modbus_map.h), and as a CAN\n"
      "node with --can (drivers/fixture/can_map.h). Stops on SIGTERM or SIGINT.");
  cmd->add_option("--config", opt->config,
                  "Station config JSON: its \"sim\" object sets up the bench, its fixture "
                  "\"map\" the register map")
      ->check(CLI::ExistingFile);
  cmd->add_option("--listen", opt->listen, "IPv4 address to listen on")->capture_default_str();
  cmd->add_option("--port", opt->port, "TCP port; 0 picks a free port (see --ready-file)")
      ->check(Between(0, 65535))
      ->capture_default_str();
  cmd->add_option("--unit-id", opt->unit_id, "Modbus unit id served")
      ->check(Between(1, 247))
      ->capture_default_str();
  cmd->add_option("--rtu", opt->rtu_device,
                  "Also serve Modbus RTU on this serial device (e.g. one end of a socat pty pair)");
  cmd->add_option("--baud", opt->baud, "RTU baud rate")->capture_default_str();
  cmd->add_option("--parity", opt->parity, "RTU parity")
      ->check(CLI::IsMember({"N", "E", "O"}))
      ->capture_default_str();
  cmd->add_option("--data-bits", opt->data_bits, "RTU data bits")
      ->check(Between(5, 8))
      ->capture_default_str();
  cmd->add_option("--stop-bits", opt->stop_bits, "RTU stop bits")
      ->check(CLI::IsMember({1, 2}))
      ->capture_default_str();
  cmd->add_option("--part", opt->part, "Load a simulated part with this serial at start");
  cmd->add_flag("--load-part-on-clamp", opt->load_part_on_clamp,
                "When clamp_cmd rises on an empty fixture, load a part \"SIM-<n>\" first");
  cmd->add_option("--fault", opt->fault, "Inject a fault: " + FaultNames());
  cmd->add_option("--fault-after-ms", opt->fault_after_ms,
                  "Delay before the fault shows, from start (or from the next excitation-enable "
                  "edge with --fault-on-excitation)")
      ->check(NonNegative())
      ->capture_default_str();
  cmd->add_flag("--fault-on-excitation", opt->fault_on_excitation,
                "Count --fault-after-ms from the next excitation-enable edge");
  cmd->add_option("--fault-duration-ms", opt->fault_duration_ms,
                  "How long the fault lasts once shown, then the fixture is healthy again "
                  "(0: until the emulator stops); the fault shows once")
      ->check(NonNegative())
      ->capture_default_str();
  cmd->add_option("--ready-file", opt->ready_file,
                  "Once serving, write the TCP port number here (written atomically)");
  cmd->add_option("--can", opt->can_interface,
                  "Also serve the bench as a CAN node on this SocketCAN interface, with the "
                  "frame map of drivers/fixture/can_map.h (the config's \"socketcan\" fixture "
                  "map, if any)");
  cmd->add_option("--node-id", opt->node_id,
                  "CAN node id served (default: the config's fixture node_id, else 1)")
      ->check(Between(1, 127));
  cmd->add_option("--status-period-ms", opt->status_period_ms, "CAN status frame period")
      ->check(Between(1, 1000))
      ->capture_default_str();
  cmd->callback([opt] { RunGuarded("fixture-sim", [opt] { return RunFixtureSim(*opt); }); });
}

}  // namespace eol::station::cli
