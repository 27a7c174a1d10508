// The CAN fixture driver and `eol fixture-sim --can` against independent peers on a real
// SocketCAN interface (EOL_CAN_INTERFACE; ctest runs this under
// tests/support/vcan/with-vcan, whose shim every child process inherits):
//   - tests/peers/can_fixture_peer.py (python3-can) playing a fixture node for our driver,
//     and as a client of our emulator; it encodes deploy/OPERATIONS.md's frame map on its own;
//   - can-utils' cansend and candump against the emulator.
// Peers are declared dependencies (deploy/install-deps.sh --tests): a missing one fails the
// test with the install hint; it never skips.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "drivers/factory/factory.h"
#include "drivers/fixture/can_fixture.h"
#include "tests/support/child_process.h"

namespace eol::drivers {
namespace {

using namespace std::chrono_literals;
using eol::testing::ChildProcess;
using eol::testing::TempDir;

#define EXPECT_CONTAINS(text, part) \
  EXPECT_NE(std::string(text).find(part), std::string::npos) << "in: " << (text)

constexpr const char* kInterface = EOL_CAN_INTERFACE;
constexpr const char* kPython = "/usr/bin/python3";

std::string Peer() { return std::string(EOL_SOURCE_DIR) + "/tests/peers/can_fixture_peer.py"; }

::testing::AssertionResult PythonCanAvailable() {
  if (access(kPython, X_OK) != 0)
    return ::testing::AssertionFailure() << kPython << " not found (python3-can is a declared "
                                         << "dependency: apt-get install python3-can)";
  ChildProcess probe({kPython, "-c", "import can; print(can.__version__)"});
  if (probe.Wait(30s) != 0)
    return ::testing::AssertionFailure() << "python3-can is missing for " << kPython
                                         << " (apt-get install python3-can): " << probe.output();
  return ::testing::AssertionSuccess();
}

::testing::AssertionResult CanUtilsAvailable() {
  for (const char* tool : {"/usr/bin/cansend", "/usr/bin/candump"})
    if (access(tool, X_OK) != 0)
      return ::testing::AssertionFailure()
             << tool
             << " not found: can-utils is a declared dependency (apt-get install can-utils)";
  return ::testing::AssertionSuccess();
}

CanFixtureSettings DriverSettings() {
  CanFixtureSettings s;
  s.interface = kInterface;
  // Generous, so that a loaded machine never trips them; tests of the timeouts set their own.
  s.status_timeout_ms = 2000;
  s.heartbeat_timeout_ms = 3000;
  s.confirm_timeout_ms = 3000;
  s.connect_timeout_ms = 5000;
  return s;
}

StatusOr<FixtureInputs> ReadUntil(Fixture& fixture,
                                  const std::function<bool(const FixtureInputs&)>& pred) {
  const auto end = std::chrono::steady_clock::now() + 10s;  // bounds a broken run only
  for (;;) {
    StatusOr<FixtureInputs> in = fixture.ReadInputs();
    if (in.ok() && pred(in.value())) return in;
    if (std::chrono::steady_clock::now() > end) return in;
    std::this_thread::sleep_for(10ms);
  }
}

Status ReadUntilError(Fixture& fixture) {
  const auto end = std::chrono::steady_clock::now() + 10s;
  while (std::chrono::steady_clock::now() < end) {
    StatusOr<FixtureInputs> in = fixture.ReadInputs();
    if (!in.ok()) return in.status();
    std::this_thread::sleep_for(10ms);
  }
  return Status::Ok();
}

// The command frames the python node printed (one JSON line each), data bytes only.
std::vector<std::vector<int>> Commands(const std::string& output) {
  std::vector<std::vector<int>> out;
  std::istringstream lines(output);
  for (std::string line; std::getline(lines, line);) {
    if (line.empty() || line[0] != '{') continue;
    const auto j = nlohmann::json::parse(line);
    if (j.at("id") == 0x201) out.push_back(j.at("data").get<std::vector<int>>());
  }
  return out;
}

std::unique_ptr<ChildProcess> StartPythonNode(const std::vector<std::string>& extra) {
  std::vector<std::string> argv = {kPython, Peer(), "node", kInterface};
  argv.insert(argv.end(), extra.begin(), extra.end());
  auto node = std::make_unique<ChildProcess>(argv, /*merge_stderr=*/true);
  EXPECT_TRUE(node->WaitFor([](const std::string& o) { return o.find("ready") != o.npos; }, 30s))
      << node->output();
  return node;
}

TEST(CanPeersTest, DriverAgainstPythonCanNode) {
  ASSERT_TRUE(PythonCanAvailable());
  auto node = StartPythonNode({"--pressure-counts", "537"});
  CanFixture fixture(DriverSettings());
  ASSERT_TRUE(fixture.Connect().ok());
  ASSERT_TRUE(fixture.Activate().ok());
  ASSERT_TRUE(fixture.Write(FixtureOutput::kClampCmd, true).ok());
  auto in = ReadUntil(fixture, [](const FixtureInputs& i) { return i.clamped; });
  ASSERT_TRUE(in.ok()) << in.status().message();
  ASSERT_TRUE(in.value().clamped);
  EXPECT_FALSE(in.value().released);
  EXPECT_DOUBLE_EQ(in.value().clamp_pressure_bar, 5.37);  // 537 counts of 0.01 bar
  ASSERT_TRUE(fixture.SelectPhasePair(PhasePair::kWU).ok());
  ASSERT_TRUE(fixture.WriteAlive(1).ok());
  ASSERT_TRUE(fixture.Write(FixtureOutput::kExcitationEnable, true).ok());
  ASSERT_TRUE(fixture.Write(FixtureOutput::kLampFail, true).ok());
  const auto heartbeat = in.value().heartbeat;
  in = ReadUntil(fixture, [&](const FixtureInputs& i) { return i.heartbeat != heartbeat; });
  ASSERT_TRUE(in.ok()) << in.status().message();
  EXPECT_NE(in.value().heartbeat, heartbeat);

  node->WaitFor([](const std::string& o) { return Commands(o).size() >= 6; }, 5s);
  const auto commands = Commands(node->output());
  // Connect (excitation off), clamp, phase pair, station_alive, excitation, lamp: the full
  // state each time, the counter counting, the alive value carried on.
  ASSERT_EQ(commands.size(), 6u) << node->output();
  const std::vector<std::vector<int>> expected = {{0x00, 0, 1, 0}, {0x01, 0, 2, 0},
                                                  {0x01, 2, 3, 0}, {0x01, 2, 4, 1},
                                                  {0x03, 2, 5, 1}, {0x0B, 2, 6, 1}};
  EXPECT_EQ(commands, expected);
}

TEST(CanPeersTest, DriverNamesAFrozenPeerHeartbeat) {
  ASSERT_TRUE(PythonCanAvailable());
  auto node = StartPythonNode({"--heartbeat-stops-after-ms", "1500"});
  CanFixtureSettings settings = DriverSettings();
  settings.heartbeat_timeout_ms = 600;
  CanFixture fixture(settings);
  ASSERT_TRUE(fixture.Connect().ok());
  const Status s = ReadUntilError(fixture);
  ASSERT_FALSE(s.ok()) << "reads kept succeeding after the peer's heartbeat stopped";
  EXPECT_CONTAINS(s.message(),
                  "no heartbeat frame 0x701 from node 1 on " + std::string(kInterface));
  EXPECT_CONTAINS(s.message(), "(heartbeat_timeout_ms 600)");
}

TEST(CanPeersTest, DriverRejectsMalformedPeerStatus) {
  ASSERT_TRUE(PythonCanAvailable());
  auto node = StartPythonNode({"--malformed-status"});
  CanFixtureSettings settings = DriverSettings();
  settings.connect_timeout_ms = 1000;
  CanFixture fixture(settings);
  const Status s = fixture.Connect();
  ASSERT_FALSE(s.ok());
  EXPECT_CONTAINS(s.message(), "connect: no well-formed status frame 0x181 from node 1");
  EXPECT_CONTAINS(s.message(), std::string(kInterface) +
                                   ": malformed status frame 0x181 from node 1: 3 data bytes, "
                                   "expected 6");
}

// `eol fixture-sim --can` with a free TCP port; ready once the ready file exists.
std::unique_ptr<ChildProcess> StartFixtureSim(const TempDir& dir,
                                              const std::vector<std::string>& extra) {
  const std::string ready = dir / "ready";
  std::vector<std::string> argv = {EOL_BINARY,     "fixture-sim", "--port", "0",
                                   "--ready-file", ready,         "--can",  kInterface};
  argv.insert(argv.end(), extra.begin(), extra.end());
  auto sim = std::make_unique<ChildProcess>(argv);
  EXPECT_TRUE(sim->WaitFor([&](const std::string&) { return std::filesystem::exists(ready); }, 30s))
      << sim->output();
  return sim;
}

TEST(CanPeersTest, FixtureSimAgainstPythonCanClient) {
  ASSERT_TRUE(PythonCanAvailable());
  TempDir dir;
  auto sim = StartFixtureSim(dir, {"--part", "SN-PY-1"});
  ChildProcess client({kPython, Peer(), "client", kInterface}, /*merge_stderr=*/false);
  ASSERT_EQ(client.Wait(60s), 0) << client.output() << sim->output();
  const auto out = nlohmann::json::parse(client.output());
  ASSERT_TRUE(out.at("first").is_object()) << out.dump();
  EXPECT_EQ(out["first"]["released"], 1);
  EXPECT_EQ(out["first"]["part_present"], 1);
  EXPECT_EQ(out["first"]["door_closed"], 1);
  EXPECT_EQ(out["first"]["estop_ok"], 1);
  ASSERT_TRUE(out.at("echo").is_object()) << out.dump();
  EXPECT_EQ(out["echo"]["lamp_pass_echo"], 1);
  EXPECT_EQ(out["echo"]["phase_pair_echo"], 1);
  EXPECT_EQ(out["echo"]["excitation_echo"], 0);
  ASSERT_TRUE(out.at("clamped").is_object()) << out.dump();
  EXPECT_NEAR(out["clamped"]["pressure_counts"].get<int>(), 550, 3);  // 5.5 bar in 0.01 bar
  ASSERT_TRUE(out.at("released").is_object()) << out.dump();
  EXPECT_EQ(out["released"]["clamped"], 0);
  EXPECT_EQ(out["status_dlc"], 6);
  EXPECT_EQ(out["nmt_state"], 5);
  const auto beats = out["heartbeats"].get<std::vector<int>>();
  ASSERT_GE(beats.size(), 2u) << out.dump();
  // Heartbeat frames every 100 ms, the counter advancing every 200 ms: steps of 0 or 1.
  for (std::size_t i = 1; i < beats.size(); ++i)
    EXPECT_LE((beats[i] - beats[i - 1] + 256) % 256, 1) << out.dump();
  EXPECT_NE(beats.front(), beats.back()) << out.dump();
  EXPECT_EQ(sim->Stop(SIGTERM, 10s), 0) << sim->output();
}

// candump -L lines "(time) vcan0 181#1E0000000000", as (id, data bytes).
std::vector<std::pair<int, std::vector<int>>> ParseCandump(const std::string& text) {
  std::vector<std::pair<int, std::vector<int>>> out;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    const auto hash = line.find('#');
    const auto space = line.rfind(' ', hash);
    if (hash == std::string::npos || space == std::string::npos) continue;
    const int id = std::stoi(line.substr(space + 1, hash - space - 1), nullptr, 16);
    std::vector<int> data;
    for (std::size_t i = hash + 1; i + 2 <= line.size(); i += 2)
      data.push_back(std::stoi(line.substr(i, 2), nullptr, 16));
    out.emplace_back(id, data);
  }
  return out;
}

TEST(CanPeersTest, FixtureSimAgainstCansendAndCandump) {
  ASSERT_TRUE(CanUtilsAvailable());
  TempDir dir;
  auto sim = StartFixtureSim(dir, {"--part", "SN-CU-1", "--fault", "door_opens"});
  ChildProcess dump({"/usr/bin/candump", "-L", std::string(kInterface) + ",181:7FF,701:7FF"});
  std::this_thread::sleep_for(200ms);  // candump binds before the command goes out
  ChildProcess send(
      {"/usr/bin/cansend", kInterface, "201#05020101"});  // clamp, lamp_pass, W-U, alive 1
  ASSERT_EQ(send.Wait(10s), 0) << send.output();
  const auto echoed = [](const std::string& o) {
    for (const auto& [id, d] : ParseCandump(o))
      if (id == 0x181 && d.size() == 6 && (d[1] & 0x05) == 0x05 && d[2] == 2 && (d[0] & 1))
        return true;  // clamped, with the command echoed
    return false;
  };
  ASSERT_TRUE(dump.WaitFor(echoed, 10s)) << dump.output();
  const auto frames = ParseCandump(dump.output());
  bool saw_heartbeat = false;
  for (const auto& [id, d] : frames) {
    if (id == 0x701) {
      ASSERT_EQ(d.size(), 2u);
      EXPECT_EQ(d[0], 0x05);
      saw_heartbeat = true;
    }
    if (id == 0x181) {
      ASSERT_EQ(d.size(), 6u);
      EXPECT_EQ(d[0] & 0x08, 0) << "door_opens: door_closed must read 0";
      EXPECT_EQ(d[0] & 0x10, 0x10) << "estop_ok";
    }
  }
  EXPECT_TRUE(saw_heartbeat);
  // A command of the wrong length is refused: the status keeps echoing the old outputs.
  ChildProcess bad({"/usr/bin/cansend", kInterface, "201#00"});
  ASSERT_EQ(bad.Wait(10s), 0);
  ASSERT_TRUE(sim->WaitFor(
      [](const std::string& o) { return o.find("malformed command frame 0x201") != o.npos; }, 10s))
      << sim->output();
  EXPECT_CONTAINS(sim->output(), "1 data bytes, expected 4");
  dump.Stop(SIGTERM, 5s);
  EXPECT_EQ(sim->Stop(SIGTERM, 10s), 0) << sim->output();
}

TEST(CanPeersTest, DriverAgainstFixtureSimUntilItStopsAnswering) {
  TempDir dir;
  auto sim = StartFixtureSim(
      dir, {"--part", "SN-FS-1", "--fault", "stops_answering", "--fault-on-excitation",
            "--fault-after-ms", "100"});  // within the alive timeout
  CanFixtureSettings settings = DriverSettings();
  settings.status_timeout_ms = 1000;
  CanFixture fixture(settings);
  ASSERT_TRUE(fixture.Connect().ok());
  ASSERT_TRUE(fixture.Activate().ok());
  ASSERT_TRUE(fixture.Write(FixtureOutput::kClampCmd, true).ok());
  auto in = ReadUntil(fixture, [](const FixtureInputs& i) { return i.clamped; });
  ASSERT_TRUE(in.ok()) << in.status().message();
  EXPECT_NEAR(in.value().clamp_pressure_bar, 5.5, 0.035);
  ASSERT_TRUE(fixture.WriteAlive(1).ok());
  ASSERT_TRUE(fixture.Write(FixtureOutput::kExcitationEnable, true).ok());
  const Status s = ReadUntilError(fixture);
  ASSERT_FALSE(s.ok());
  EXPECT_CONTAINS(s.message(), "no status frame 0x181 from node 1 on " + std::string(kInterface));
  EXPECT_CONTAINS(s.message(), "(status_timeout_ms 1000)");
  ASSERT_TRUE(sim->WaitFor(
      [](const std::string& o) { return o.find("excitation relay dropped out") != o.npos; }, 10s))
      << sim->output();
  EXPECT_EQ(sim->Stop(SIGTERM, 10s), 0) << sim->output();
}

TEST(CanPeersTest, FixtureSimAndDriverShareTheStationConfig) {
  // One config file for both ends: node id 7 and the pressure moved to bytes 6..7.
  TempDir dir;
  nlohmann::json config = R"({
    "fixture": {"driver": "socketcan", "interface": "can9", "node_id": 7,
                "status_timeout_ms": 2000, "heartbeat_timeout_ms": 3000,
                "confirm_timeout_ms": 3000, "connect_timeout_ms": 5000,
                "map": {"clamp_pressure": {"byte": 6}}},
    "daq": {"driver": "sim"}})"_json;
  config["fixture"]["interface"] = kInterface;
  const std::string path = dir / "station.json";
  std::ofstream(path) << config.dump(2);
  auto sim = StartFixtureSim(dir, {"--config", path, "--part", "SN-CFG-1"});
  DriverSet set = MakeDrivers(config);
  ASSERT_TRUE(set.fixture->Connect().ok());
  ASSERT_TRUE(set.fixture->Activate().ok());
  ASSERT_TRUE(set.fixture->Write(FixtureOutput::kClampCmd, true).ok());
  const auto in = ReadUntil(*set.fixture, [](const FixtureInputs& i) { return i.clamped; });
  ASSERT_TRUE(in.ok()) << in.status().message();
  EXPECT_NEAR(in.value().clamp_pressure_bar, 5.5, 0.035);
  set.fixture->Disconnect();
  const std::string line = "CAN node 7 on " + std::string(kInterface) +
                           " (command 0x207, status 0x187, heartbeat 0x707)";
  EXPECT_TRUE(sim->WaitFor([&](const std::string& o) { return o.find(line) != o.npos; }, 10s))
      << sim->output();
  EXPECT_EQ(sim->Stop(SIGTERM, 10s), 0) << sim->output();
}

}  // namespace
}  // namespace eol::drivers
