// `eol fixture-sim` (the built binary, EOL_BINARY) against an independent Modbus client,
// python3-pymodbus 3.0 (tests/peers/pymodbus_fixture_client.py), over TCP on 127.0.0.1 and
// over RTU through a socat pseudo-terminal pair; then the station's own ModbusFixture
// (modbus-rtu) on the same line. Every process is started here, waited for until ready (the
// emulator's --ready-file, socat's "PTY is" lines) and stopped by its own pid.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include "drivers/fixture/modbus_fixture.h"
#include "tests/peers/modbus_peer_support.h"
#include "tests/support/child_process.h"

namespace eol::drivers {
namespace {

using namespace std::chrono_literals;
using nlohmann::json;
using testing::ChildProcess;
using testing::TempDir;
namespace peers = testing::modbus_peers;

::testing::AssertionResult EolBinaryBuilt() {
  if (access(EOL_BINARY, X_OK) == 0) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << EOL_BINARY << " is missing: build the eol target";
}

// The emulator, running until Stop() or destruction.
class FixtureSim {
 public:
  FixtureSim(const TempDir& dir, std::vector<std::string> args) : ready_file_(dir / "sim.port") {
    std::vector<std::string> argv = {EOL_BINARY, "fixture-sim",  "--port",
                                     "0",        "--ready-file", ready_file_};
    argv.insert(argv.end(), args.begin(), args.end());
    process_ = std::make_unique<ChildProcess>(argv);
    port_ = peers::WaitForReadyPort(*process_, ready_file_, 20s);
  }
  std::optional<int> port() const { return port_; }
  std::string tcp() const { return "127.0.0.1:" + std::to_string(port_.value_or(0)); }
  const std::string& output() const { return process_->output(); }
  std::optional<int> Stop() { return process_->Stop(SIGTERM, 10s); }

 private:
  std::string ready_file_;
  std::unique_ptr<ChildProcess> process_;
  std::optional<int> port_;
};

// One result of the client per operation, in order.
void ExpectValues(const json& result, const std::vector<int>& values) {
  EXPECT_EQ(result.value("values", json()), json(values)) << result.dump();
}
void ExpectOk(const json& result) { EXPECT_EQ(result.value("ok", false), true) << result.dump(); }
void ExpectException(const json& result, int code) {
  EXPECT_EQ(result.value("exception_code", -1), code) << result.dump();
}
void ExpectNoAnswer(const json& result) { EXPECT_TRUE(result.contains("error")) << result.dump(); }

// The same conversation over either transport; the bench starts empty and loads a part when
// the clamp closes (--load-part-on-clamp).
void ExpectConversation(const std::vector<std::string>& transport, bool tcp) {
  const json ops = json::parse(R"([
      ["read_di", 0, 5], ["read_ir", 0, 2], ["read_coils", 0, 4], ["read_hr", 0, 1],
      ["write_coil", 0, 1], ["read_di", 0, 5], ["sleep", 0.3], ["read_di", 0, 5],
      ["read_ir", 0, 2],
      ["write_hrs", 0, [2, 1]], ["read_hr", 0, 1], ["write_hr", 0, 7], ["read_hr", 0, 1],
      ["write_coils", 1, [1, 1, 0]], ["read_coils", 0, 4],
      ["mask_write_hr", 0, 1, 2], ["read_di", 0, 6],
      ["read_di", 0, 5, {"unit": 2}], ["read_di", 0, 5], ["read_di", 0, 5]])");
  std::string log;
  const json r = peers::RunPymodbusClient(transport, ops, &log);
  ASSERT_TRUE(r.is_array()) << log;
  ASSERT_EQ(r.size(), ops.size()) << log;
  ExpectValues(r[0], {0, 1, 0, 1, 1});  // released, no part, door closed, e-stop healthy
  ASSERT_TRUE(r[1].contains("values")) << r[1].dump();
  EXPECT_EQ(r[1]["values"][0], 0);  // no pressure while open
  ExpectValues(r[2], {0, 0, 0, 0});
  ExpectValues(r[3], {0});
  ExpectOk(r[4]);                       // clamp_cmd: loads part SIM-1, clamp starts closing
  ExpectValues(r[5], {0, 0, 1, 1, 1});  // neither clamped nor released within 150 ms
  ExpectValues(r[7], {1, 0, 1, 1, 1});  // clamped after clamp_close_s
  ASSERT_TRUE(r[8].contains("values")) << r[8].dump();
  EXPECT_NEAR(r[8]["values"][0].get<int>(), 550, 3);  // 5.5 bar in 0.01 bar counts, ripple
  EXPECT_GT(r[8]["values"][1].get<int>(), r[1]["values"][1].get<int>());  // heartbeat moved
  ExpectOk(r[9]);  // phase_pair 2 and station_alive 1: the relay may close (modbus_map.h)
  ExpectValues(r[10], {2});
  ExpectException(r[11], 3);  // phase_pair 7: illegal data value, and nothing changed
  ExpectValues(r[12], {2});
  ExpectOk(r[13]);
  ExpectValues(r[14], {1, 1, 1, 0});
  ExpectException(r[15], 1);  // mask write: illegal function on this controller
  ExpectException(r[16], 2);  // discrete input 5 is not in the map: illegal data address
  if (tcp) {
    ExpectException(r[17], 11);  // TCP: another unit id gets "gateway target failed"
    ExpectValues(r[18], {1, 0, 1, 1, 1});
  } else {
    ExpectNoAnswer(r[17]);  // RTU: another unit's request is not ours to answer...
    ExpectNoAnswer(r[18]);  // ...and the next frame is taken for that unit's reply (libmodbus)
  }
  ExpectValues(r[19], {1, 0, 1, 1, 1});
}

TEST(FixtureSimPymodbusPeerTest, ServesTheDefaultMapOverTcp) {
  ASSERT_TRUE(EolBinaryBuilt());
  ASSERT_TRUE(peers::PymodbusAvailable());
  TempDir dir;
  FixtureSim sim(dir, {"--load-part-on-clamp"});
  ASSERT_TRUE(sim.port()) << "eol fixture-sim not ready: " << sim.output();
  ExpectConversation({"--tcp", sim.tcp()}, /*tcp=*/true);
  EXPECT_EQ(sim.Stop(), 0) << sim.output();  // SIGTERM stops it cleanly
  EXPECT_NE(sim.output().find("SIGTERM received"), std::string::npos) << sim.output();
}

TEST(FixtureSimPymodbusPeerTest, StopsAnsweringReallyStopsAnswering) {
  ASSERT_TRUE(EolBinaryBuilt());
  ASSERT_TRUE(peers::PymodbusAvailable());
  TempDir dir;
  // The controller dies the moment excitation is switched on (the write itself is answered).
  FixtureSim sim(dir, {"--part", "P-0001", "--fault", "stops_answering", "--fault-after-ms", "0",
                       "--fault-on-excitation"});
  ASSERT_TRUE(sim.port()) << "eol fixture-sim not ready: " << sim.output();
  std::string log;
  const json r = peers::RunPymodbusClient(
      {"--tcp", sim.tcp()},
      json::parse(R"([["read_di", 0, 5], ["write_hr", 1, 1], ["write_coil", 1, 1],
                      ["read_di", 0, 5], ["read_coils", 0, 4]])"),
      &log);
  ASSERT_TRUE(r.is_array()) << log;
  ExpectValues(r[0], {0, 1, 1, 1, 1});
  ExpectOk(r[1]);  // station_alive: without it the relay does not close (modbus_map.h)
  ExpectOk(r[2]);
  ExpectNoAnswer(r[3]);
  ExpectNoAnswer(r[4]);
  EXPECT_EQ(sim.Stop(), 0) << sim.output();
}

TEST(FixtureSimPymodbusPeerTest, ConfigSetsTheBenchAndTheMap) {
  ASSERT_TRUE(EolBinaryBuilt());
  ASSERT_TRUE(peers::PymodbusAvailable());
  TempDir dir;
  {
    std::ofstream config(dir / "station.json");
    config << R"({"sim": {"clamp_pressure_bar": 4.0, "clamp_close_s": 0.05},
                  "fixture": {"driver": "modbus-tcp", "map": {"clamp_pressure": 5,
                              "pressure_bar_per_count": 0.1}}})";
  }
  FixtureSim sim(dir, {"--config", dir / "station.json", "--part", "P-0002"});
  ASSERT_TRUE(sim.port()) << "eol fixture-sim not ready: " << sim.output();
  std::string log;
  const json r = peers::RunPymodbusClient(
      {"--tcp", sim.tcp()},
      json::parse(R"([["write_coil", 0, 1], ["sleep", 0.2], ["read_ir", 5, 1]])"), &log);
  ASSERT_TRUE(r.is_array()) << log;
  ASSERT_TRUE(r[2].contains("values")) << r[2].dump();
  EXPECT_EQ(r[2]["values"][0], 40);  // 4.0 bar at 0.1 bar per count
  EXPECT_EQ(sim.Stop(), 0) << sim.output();
}

TEST(FixtureSimPymodbusPeerTest, UnknownFaultIsRefusedWithTheKnownNames) {
  ASSERT_TRUE(EolBinaryBuilt());
  ChildProcess sim({EOL_BINARY, "fixture-sim", "--port", "0", "--fault", "bogus"});
  EXPECT_EQ(sim.Wait(20s), 2) << sim.output();
  EXPECT_NE(sim.output().find("unknown fault 'bogus' (known: stops_answering, clamp_drops, "),
            std::string::npos)
      << sim.output();
}

// socat's two pseudo-terminals, parsed from its "-d -d" notices.
class PtyPair {
 public:
  PtyPair() : process_({peers::kSocat, "-d", "-d", "pty,raw,echo=0", "pty,raw,echo=0"}) {
    const std::regex pty("PTY is (/dev/pts/[0-9]+)");
    process_.WaitFor(
        [&](const std::string& text) {
          names_.clear();
          for (std::sregex_iterator it(text.begin(), text.end(), pty), end; it != end; ++it)
            names_.push_back((*it)[1]);
          return names_.size() == 2 &&
                 text.find("starting data transfer loop") != std::string::npos;
        },
        10s);
  }
  ~PtyPair() { process_.Stop(SIGTERM, 5s); }
  bool ready() const { return names_.size() == 2; }
  const std::string& a() const { return names_[0]; }
  const std::string& b() const { return names_[1]; }
  const std::string& output() const { return process_.output(); }

 private:
  ChildProcess process_;
  std::vector<std::string> names_;
};

TEST(FixtureSimPymodbusPeerTest, ServesTheDefaultMapOverRtuOnAPtyPair) {
  ASSERT_TRUE(EolBinaryBuilt());
  ASSERT_TRUE(peers::PymodbusAvailable());
  ASSERT_TRUE(peers::SocatAvailable());
  PtyPair line;
  ASSERT_TRUE(line.ready()) << "socat: " << line.output();
  // No parity on a pty: pyserial cannot reconfigure a pty with parity (EINVAL), and a
  // pseudo-terminal carries no parity bit anyway.
  TempDir dir;
  FixtureSim sim(dir,
                 {"--rtu", line.a(), "--baud", "19200", "--parity", "N", "--load-part-on-clamp"});
  ASSERT_TRUE(sim.port()) << "eol fixture-sim not ready: " << sim.output();
  ExpectConversation({"--rtu", line.b(), "--baud", "19200", "--parity", "N"}, /*tcp=*/false);

  // The station's own RTU driver on the same line, after the python client let go of it.
  ModbusFixtureSettings s;
  s.link.transport = ModbusLink::Transport::kRtu;
  s.link.device = line.b();
  s.link.baud = 19200;
  s.link.parity = 'N';
  s.response_timeout_ms = 500;
  ModbusFixture fixture(s);
  const Status c = fixture.Connect();
  ASSERT_TRUE(c.ok()) << c.message();
  const auto in = fixture.ReadInputs();
  ASSERT_TRUE(in.ok()) << in.status().message();
  EXPECT_TRUE(in.value().clamped);  // the python client left the clamp closed
  EXPECT_TRUE(in.value().part_present);
  EXPECT_NEAR(in.value().clamp_pressure_bar, 5.5, 0.03);
  ASSERT_TRUE(fixture.Activate().ok());
  ASSERT_TRUE(fixture.SelectPhasePair(PhasePair::kWU).ok());
  ASSERT_TRUE(fixture.Write(FixtureOutput::kClampCmd, false).ok());
  fixture.Disconnect();  // excitation off, then close the line

  std::string log;
  const json r =
      peers::RunPymodbusClient({"--rtu", line.b(), "--baud", "19200", "--parity", "N"},
                               json::parse(R"([["read_hr", 0, 1], ["read_coils", 0, 4]])"), &log);
  ASSERT_TRUE(r.is_array()) << log;
  ExpectValues(r[0], {2});
  ExpectValues(r[1], {0, 0, 1, 0});  // clamp open, excitation off, lamps as the client left
  EXPECT_EQ(sim.Stop(), 0) << sim.output();
}

}  // namespace
}  // namespace eol::drivers
