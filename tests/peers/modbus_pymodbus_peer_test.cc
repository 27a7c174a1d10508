// The station's Modbus fixture driver (ModbusFixture, modbus-tcp) against an independent
// controller: a python3-pymodbus 3.0 TCP server holding the default map, unit 1,
// zero_mode=True (tests/peers/pymodbus_fixture_server.py), started here on a free port,
// waited for through its ready file and stopped by its own pid. Every input is read with a
// known answer (each bit pattern and its complement, and the full-scale pressure count);
// every write is checked in the state the server mirrors to a JSON file.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <memory>
#include <ostream>
#include <string>
#include <thread>
#include <vector>

#include "drivers/fixture/modbus_fixture.h"
#include "tests/peers/modbus_peer_support.h"
#include "tests/support/child_process.h"

namespace eol::drivers {
namespace {

using namespace std::chrono_literals;
using testing::ChildProcess;
using testing::TempDir;
namespace peers = testing::modbus_peers;

// The python controller, running until Stop() or destruction.
class PymodbusServer {
 public:
  PymodbusServer(const TempDir& dir, const std::string& discrete, int pressure_counts,
                 int heartbeat_start)
      : ready_file_(dir / "server.port"), state_file_(dir / "server.state.json") {
    process_ = std::make_unique<ChildProcess>(std::vector<std::string>{
        peers::kPython, peers::PeerScript("pymodbus_fixture_server.py"), "--port", "0", "--unit",
        "1", "--discrete", discrete, "--pressure-counts", std::to_string(pressure_counts),
        "--heartbeat-start", std::to_string(heartbeat_start), "--heartbeat-ms", "100",
        "--ready-file", ready_file_, "--state-file", state_file_});
    port_ = peers::WaitForReadyPort(*process_, ready_file_, 20s);
  }
  ~PymodbusServer() { Stop(); }

  std::optional<int> port() const { return port_; }
  const std::string& output() const { return process_->output(); }
  std::optional<int> Stop() { return process_->Stop(SIGTERM, 10s); }

  // The coils and holding registers as last written, once they equal `want` (or after 2 s).
  nlohmann::json StateWhen(const nlohmann::json& want) const {
    nlohmann::json state;
    const auto deadline = std::chrono::steady_clock::now() + 2s;
    do {
      std::ifstream in(state_file_);
      try {
        state = nlohmann::json::parse(in);
      } catch (const nlohmann::json::exception&) {
        state = nullptr;
      }
      if (state == want) break;
      std::this_thread::sleep_for(10ms);
    } while (std::chrono::steady_clock::now() < deadline);
    return state;
  }

 private:
  std::string ready_file_, state_file_;
  std::unique_ptr<ChildProcess> process_;
  std::optional<int> port_;
};

ModbusFixtureSettings ClientFor(int port) {
  ModbusFixtureSettings s;
  s.link.host = "127.0.0.1";
  s.link.port = port;
  s.link.unit_id = 1;
  s.response_timeout_ms = 500;
  s.attempts = 2;
  return s;
}

struct InputPattern {
  std::string discrete;  // clamped,released,part_present,door_closed,estop_ok
  int pressure_counts;
  double pressure_bar;  // the known answer at 0.01 bar per count
};

void PrintTo(const InputPattern& p, std::ostream* os) {
  *os << "discrete " << p.discrete << ", pressure " << p.pressure_counts << " counts";
}

std::string PatternName(const ::testing::TestParamInfo<InputPattern>& info) {
  std::string name = "Bits";
  for (char c : info.param.discrete)
    if (c != ',') name += c;
  return name + "Counts" + std::to_string(info.param.pressure_counts);
}

class ModbusPymodbusReadTest : public ::testing::TestWithParam<InputPattern> {};

TEST_P(ModbusPymodbusReadTest, EveryInputReadsWithItsKnownAnswer) {
  ASSERT_TRUE(peers::PymodbusAvailable());
  const InputPattern& p = GetParam();
  TempDir dir;
  PymodbusServer server(dir, p.discrete, p.pressure_counts, 100);
  ASSERT_TRUE(server.port()) << "pymodbus server not ready: " << server.output();

  ModbusFixture fixture(ClientFor(*server.port()));
  const Status c = fixture.Connect();
  ASSERT_TRUE(c.ok()) << c.message();
  const auto in = fixture.ReadInputs();
  ASSERT_TRUE(in.ok()) << in.status().message();
  const auto bit = [&](int i) { return p.discrete[static_cast<std::size_t>(2 * i)] == '1'; };
  EXPECT_EQ(in.value().clamped, bit(0));
  EXPECT_EQ(in.value().released, bit(1));
  EXPECT_EQ(in.value().part_present, bit(2));
  EXPECT_EQ(in.value().door_closed, bit(3));
  EXPECT_EQ(in.value().estop_ok, bit(4));
  EXPECT_NEAR(in.value().clamp_pressure_bar, p.pressure_bar, 1e-9);
  EXPECT_GE(in.value().heartbeat, 100u);

  // The server beats every 100 ms; the driver must see it move within 500 ms.
  std::this_thread::sleep_for(500ms);
  const auto later = fixture.ReadInputs();
  ASSERT_TRUE(later.ok()) << later.status().message();
  EXPECT_GE(later.value().heartbeat, in.value().heartbeat + 2);

  fixture.Disconnect();
  EXPECT_EQ(server.Stop(), 0) << server.output();
}

INSTANTIATE_TEST_SUITE_P(Patterns, ModbusPymodbusReadTest,
                         ::testing::Values(InputPattern{"1,0,1,0,1", 553, 5.53},
                                           InputPattern{"0,1,0,1,0", 0, 0.0},
                                           InputPattern{"1,1,1,1,1", 65535, 655.35}),
                         PatternName);

TEST(ModbusPymodbusPeerTest, EveryWriteLandsAtItsAddress) {
  ASSERT_TRUE(peers::PymodbusAvailable());
  TempDir dir;
  PymodbusServer server(dir, "0,1,1,1,1", 0, 0);
  ASSERT_TRUE(server.port()) << "pymodbus server not ready: " << server.output();
  ModbusFixture fixture(ClientFor(*server.port()));
  ASSERT_TRUE(fixture.Connect().ok());
  ASSERT_TRUE(fixture.Activate().ok());

  const auto state = [](std::vector<int> coils, int phase_pair) {
    return nlohmann::json{{"coils", coils}, {"holding_registers", {phase_pair}}};
  };
  // One output at a time, so that each lands on its own coil and nowhere else.
  ASSERT_TRUE(fixture.Write(FixtureOutput::kClampCmd, true).ok());
  EXPECT_EQ(server.StateWhen(state({1, 0, 0, 0}, 0)), state({1, 0, 0, 0}, 0));
  ASSERT_TRUE(fixture.Write(FixtureOutput::kExcitationEnable, true).ok());
  EXPECT_EQ(server.StateWhen(state({1, 1, 0, 0}, 0)), state({1, 1, 0, 0}, 0));
  ASSERT_TRUE(fixture.Write(FixtureOutput::kLampPass, true).ok());
  EXPECT_EQ(server.StateWhen(state({1, 1, 1, 0}, 0)), state({1, 1, 1, 0}, 0));
  ASSERT_TRUE(fixture.Write(FixtureOutput::kLampFail, true).ok());
  EXPECT_EQ(server.StateWhen(state({1, 1, 1, 1}, 0)), state({1, 1, 1, 1}, 0));
  ASSERT_TRUE(fixture.Write(FixtureOutput::kClampCmd, false).ok());
  EXPECT_EQ(server.StateWhen(state({0, 1, 1, 1}, 0)), state({0, 1, 1, 1}, 0));
  ASSERT_TRUE(fixture.Deactivate().ok());  // drives excitation off
  EXPECT_EQ(server.StateWhen(state({0, 0, 1, 1}, 0)), state({0, 0, 1, 1}, 0));

  ASSERT_TRUE(fixture.Activate().ok());
  for (PhasePair p : {PhasePair::kVW, PhasePair::kWU, PhasePair::kUV}) {
    ASSERT_TRUE(fixture.SelectPhasePair(p).ok());
    const auto want = state({0, 0, 1, 1}, static_cast<int>(p));
    EXPECT_EQ(server.StateWhen(want), want);
  }
  fixture.Disconnect();
  EXPECT_EQ(server.Stop(), 0) << server.output();
}

TEST(ModbusPymodbusPeerTest, AnotherUnitIdIsNotAnsweredAndTheErrorSaysSo) {
  // pymodbus drops a request for a unit it does not hold: the driver times out and names the
  // unit, the request, the attempt and the timeout.
  ASSERT_TRUE(peers::PymodbusAvailable());
  TempDir dir;
  PymodbusServer server(dir, "0,1,1,1,1", 0, 0);
  ASSERT_TRUE(server.port()) << "pymodbus server not ready: " << server.output();
  ModbusFixtureSettings s = ClientFor(*server.port());
  s.link.unit_id = 2;
  s.response_timeout_ms = 200;
  s.attempts = 1;
  ModbusFixture fixture(s);
  const Status c = fixture.Connect();
  ASSERT_FALSE(c.ok());
  const std::string endpoint = "127.0.0.1:" + std::to_string(*server.port());
  EXPECT_NE(c.message().find("fixture 'modbus-tcp': connect: write coil 1 (excitation_enable) = "
                             "0 at " +
                             endpoint + " unit 2: "),
            std::string::npos)
      << c.message();
  EXPECT_NE(c.message().find("(attempt 1, timeout 200 ms)"), std::string::npos) << c.message();
  EXPECT_EQ(server.Stop(), 0) << server.output();
}

}  // namespace
}  // namespace eol::drivers
