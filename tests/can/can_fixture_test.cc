// The CAN fixture driver against the CAN fixture node (the emulator behind `eol fixture-sim
// --can`), both in-process, over a real SocketCAN interface (EOL_CAN_INTERFACE; ctest runs
// this under tests/support/vcan/with-vcan): what is CAN's own beyond the fixture contract
// (tests/support/fixture_contract.h, run in can_fixture_contract_test.cc): whole-state
// command frames, pressure scaling at the driver edge, node ids from config, the heartbeat
// and status timeouts, malformed frames, bus-off through the transport seam, and the frame
// map's validation. The bench runs on a ManualClock: the clamp's travel is stated by
// advancing it. The independent peers (python3-can, can-utils) are in can_peers_test.cc.
#include "drivers/fixture/can_fixture.h"

#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <thread>

#include "drivers/emulators/can_fixture_node.h"
#include "drivers/factory/factory.h"
#include "drivers/fixture/can_link.h"
#include "drivers/fixture/can_map.h"
#include "drivers/sim/sim_bench.h"
#include "drivers/sim/sim_clock.h"

namespace eol::drivers {
namespace {

using namespace std::chrono_literals;

#define EXPECT_CONTAINS(text, part) \
  EXPECT_NE(std::string(text).find(part), std::string::npos) << "in: " << (text)

constexpr const char* kInterface = EOL_CAN_INTERFACE;

// Polls `fixture` until `pred(inputs)` holds; the last read's status otherwise. The
// deadline only bounds a broken run: it is no pass/fail threshold.
StatusOr<FixtureInputs> ReadUntil(Fixture& fixture,
                                  const std::function<bool(const FixtureInputs&)>& pred,
                                  std::chrono::milliseconds deadline = 10s) {
  const auto end = std::chrono::steady_clock::now() + deadline;
  for (;;) {
    StatusOr<FixtureInputs> in = fixture.ReadInputs();
    if (in.ok() && pred(in.value())) return in;
    if (std::chrono::steady_clock::now() > end) return in;
    std::this_thread::sleep_for(10ms);
  }
}

// Polls until a read fails; its status (or an ok status when none failed).
Status ReadUntilError(Fixture& fixture, std::chrono::milliseconds deadline = 10s) {
  const auto end = std::chrono::steady_clock::now() + deadline;
  while (std::chrono::steady_clock::now() < end) {
    StatusOr<FixtureInputs> in = fixture.ReadInputs();
    if (!in.ok()) return in.status();
    std::this_thread::sleep_for(10ms);
  }
  return Status::Ok();
}

class CanFixtureTest : public ::testing::Test {
 protected:
  void SetUp() override {
    SimBenchSettings bench_settings;
    bench_settings.clamp_pressure_bar = 5.5;
    bench_ = std::make_shared<SimBench>(bench_settings, ManualClock::Of(clock_));
    bench_->LoadPart("SN-CAN-1");
    node_settings_.interface = kInterface;
    settings_.interface = kInterface;
    // Generous, so that a loaded machine never trips them; tests of the timeouts set their own.
    settings_.status_timeout_ms = 2000;
    settings_.heartbeat_timeout_ms = 3000;
    settings_.confirm_timeout_ms = 3000;
    settings_.connect_timeout_ms = 5000;
  }

  void StartNode() {
    node_ = std::make_unique<CanFixtureNode>(bench_, node_settings_);
    const Status s = node_->Start();
    ASSERT_TRUE(s.ok()) << s.message();
  }

  std::shared_ptr<ManualClock> clock_ = std::make_shared<ManualClock>();
  std::shared_ptr<SimBench> bench_;
  CanFixtureNodeSettings node_settings_;
  CanFixtureSettings settings_;
  std::unique_ptr<CanFixtureNode> node_;
};

// Each write sends the whole command frame: the phase pair and the other outputs ride
// along, so one lost frame is repaired by the next.
TEST_F(CanFixtureTest, EveryWriteCarriesTheWholeCommand) {
  StartNode();
  CanFixture fixture(settings_);
  ASSERT_TRUE(fixture.Connect().ok());
  ASSERT_TRUE(fixture.Activate().ok());
  ASSERT_TRUE(fixture.Write(FixtureOutput::kClampCmd, true).ok());
  ASSERT_TRUE(fixture.SelectPhasePair(PhasePair::kVW).ok());
  ASSERT_TRUE(fixture.WriteAlive(1).ok());
  ASSERT_TRUE(fixture.Write(FixtureOutput::kExcitationEnable, true).ok());
  EXPECT_EQ(bench_->phase_pair(), PhasePair::kVW) << "each command carries the phase pair";
  ASSERT_TRUE(fixture.Write(FixtureOutput::kLampPass, true).ok());
  EXPECT_TRUE(bench_->excitation_connected()) << "a lamp write dropped the excitation";
  EXPECT_TRUE(bench_->output(FixtureOutput::kClampCmd)) << "full state each time";
  EXPECT_EQ(bench_->phase_pair(), PhasePair::kVW);
}

TEST_F(CanFixtureTest, PressureScaleIsTheDrivers) {
  // The node counts in 0.01 bar; a driver told 0.001 bar per count reads a tenth.
  StartNode();
  bench_->Write(FixtureOutput::kClampCmd, true);
  clock_->AdvanceSeconds(bench_->settings().clamp_close_s + 0.01);
  settings_.map.pressure_bar_per_count = 0.001;
  CanFixture fixture(settings_);
  ASSERT_TRUE(fixture.Connect().ok());
  const auto in = ReadUntil(fixture, [](const FixtureInputs& i) { return i.clamped; });
  ASSERT_TRUE(in.ok()) << in.status().message();
  ASSERT_TRUE(in.value().clamped);
  EXPECT_NEAR(in.value().clamp_pressure_bar, 0.55, 0.0035);
}

TEST_F(CanFixtureTest, OtherNodeIdAndIdsFromConfig) {
  nlohmann::json config = R"({
    "fixture": {"driver": "socketcan", "interface": "can9", "node_id": 5,
                "status_timeout_ms": 2000, "confirm_timeout_ms": 3000,
                "map": {"status_base_id": 1024, "clamp_pressure": {"byte": 6},
                        "pressure_bar_per_count": 0.01}},
    "daq": {"driver": "sim"}})"_json;
  config["fixture"]["interface"] = kInterface;
  DriverSet set = MakeDrivers(config);
  auto* can = dynamic_cast<CanFixture*>(set.fixture.get());
  ASSERT_NE(can, nullptr);
  EXPECT_EQ(can->settings().map.status_id(), 0x405u);
  EXPECT_EQ(can->settings().map.command_id(), 0x205u);
  EXPECT_EQ(can->settings().map.Dlc(CanFrameKind::kStatus), 8);

  node_settings_.map = can->settings().map;
  StartNode();
  bench_->Write(FixtureOutput::kClampCmd, true);
  clock_->AdvanceSeconds(bench_->settings().clamp_close_s + 0.01);
  ASSERT_TRUE(set.fixture->Connect().ok());
  const auto in = ReadUntil(*set.fixture, [](const FixtureInputs& i) { return i.clamped; });
  ASSERT_TRUE(in.ok()) << in.status().message();
  EXPECT_NEAR(in.value().clamp_pressure_bar, 5.5, 0.035);

  // A node on id 1 is not the configured node 5: connect names what it waited for.
  set.fixture->Disconnect();
  node_.reset();
  node_settings_.map = CanMap{};
  StartNode();
  const Status s = set.fixture->Connect();
  ASSERT_FALSE(s.ok());
  EXPECT_CONTAINS(s.message(), "no status frame 0x405 from node 5 on " + std::string(kInterface));
  EXPECT_CONTAINS(s.message(), "connect_timeout_ms");
}

TEST_F(CanFixtureTest, HeartbeatFreezesNamesTheTimeout) {
  settings_.heartbeat_timeout_ms = 600;
  StartNode();
  CanFixture fixture(settings_);
  ASSERT_TRUE(fixture.Connect().ok());
  ASSERT_TRUE(fixture.ReadInputs().ok());
  bench_->InjectFault(SimFault::kHeartbeatFreezes, 0ms, /*on_excitation=*/false);
  const Status s = ReadUntilError(fixture);
  ASSERT_FALSE(s.ok()) << "reads kept succeeding with a frozen heartbeat";
  EXPECT_CONTAINS(s.message(),
                  "fixture 'socketcan': read inputs: no heartbeat frame 0x701 "
                  "from node 1 on " +
                      std::string(kInterface));
  EXPECT_CONTAINS(s.message(), "(heartbeat_timeout_ms 600)");
  EXPECT_EQ(fixture.lifecycle(), Lifecycle::kError);
}

TEST_F(CanFixtureTest, StopsAnsweringNamesTheTimeoutAndDropsTheRelay) {
  settings_.status_timeout_ms = 300;
  settings_.confirm_timeout_ms = 1000;
  settings_.connect_timeout_ms = 1000;
  StartNode();
  CanFixture fixture(settings_);
  ASSERT_TRUE(fixture.Connect().ok());
  ASSERT_TRUE(fixture.Activate().ok());
  ASSERT_TRUE(fixture.WriteAlive(1).ok());
  ASSERT_TRUE(fixture.Write(FixtureOutput::kExcitationEnable, true).ok());
  ASSERT_TRUE(bench_->excitation_connected());
  bench_->InjectFault(SimFault::kStopsAnswering, 0ms, /*on_excitation=*/false);
  const Status s = ReadUntilError(fixture);
  ASSERT_FALSE(s.ok());
  EXPECT_CONTAINS(s.message(), "no status frame 0x181 from node 1");
  EXPECT_CONTAINS(s.message(), "(status_timeout_ms 300)");
  EXPECT_FALSE(bench_->excitation_connected()) << "a dead node drops its relay";

  // A write gets no echo: the error names the write, the frame and the timeout.
  ASSERT_TRUE(fixture.Connect().ok() == false);
  bench_->ClearFaults();
  ASSERT_TRUE(fixture.Connect().ok());
  ASSERT_TRUE(fixture.Activate().ok());
  bench_->InjectFault(SimFault::kStopsAnswering, 0ms, /*on_excitation=*/false);
  const Status w = fixture.Write(FixtureOutput::kLampFail, true);
  ASSERT_FALSE(w.ok());
  EXPECT_CONTAINS(w.message(),
                  "write lamp_fail=1: command frame 0x201 (lamp_fail = 1): no "
                  "status frame 0x181 from node 1");
  EXPECT_CONTAINS(w.message(), "(confirm_timeout_ms)");
}

TEST_F(CanFixtureTest, LampWriteNeverReenergisesADroppedRelay) {
  StartNode();
  CanFixture fixture(settings_);
  ASSERT_TRUE(fixture.Connect().ok());
  ASSERT_TRUE(fixture.Activate().ok());
  ASSERT_TRUE(fixture.WriteAlive(1).ok());
  ASSERT_TRUE(fixture.Write(FixtureOutput::kExcitationEnable, true).ok());
  bench_->InjectFault(SimFault::kStopsAnswering, 0ms, /*on_excitation=*/false);
  ASSERT_FALSE(ReadUntilError(fixture).ok());
  ASSERT_FALSE(bench_->excitation_connected());
  bench_->ClearFaults();  // the controller comes back; the fixture is in kError
  ASSERT_EQ(fixture.lifecycle(), Lifecycle::kError);
  const Status s = fixture.Write(FixtureOutput::kLampFail, true);  // allowed in kError
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_TRUE(bench_->output(FixtureOutput::kLampFail));
  EXPECT_FALSE(bench_->output(FixtureOutput::kExcitationEnable))
      << "a lamp write re-energised the excitation relay";
}

TEST_F(CanFixtureTest, MalformedStatusFrameIsNamed) {
  settings_.status_timeout_ms = 10000;  // so that the first failure is the malformed frame
  settings_.heartbeat_timeout_ms = 10000;
  StartNode();
  CanFixture fixture(settings_);
  ASSERT_TRUE(fixture.Connect().ok());
  node_.reset();  // the node goes quiet; a rogue sender on the bus takes over
  SocketCanPort rogue(kInterface, {}, false);
  CanFrame f;
  f.id = 0x181;
  f.dlc = 3;
  f.data = {0x1F, 0x00, 0x00};
  rogue.Send(f);
  const Status s = ReadUntilError(fixture);
  ASSERT_FALSE(s.ok());
  EXPECT_CONTAINS(s.message(), std::string(kInterface) +
                                   ": malformed status frame 0x181 from node 1: 3 data bytes, "
                                   "expected 6 (0x181 [3] 1F 00 00)");
}

// The transport seam: the real port, plus the error frame a kernel sends on bus-off (which
// the user-space vcan cannot produce).
class BusOffPort final : public CanPort {
 public:
  BusOffPort(std::unique_ptr<CanPort> real, std::shared_ptr<std::atomic<bool>> bus_off)
      : real_(std::move(real)), bus_off_(std::move(bus_off)) {}
  void Send(const CanFrame& f) override { real_->Send(f); }
  std::optional<CanFrame> Receive(std::chrono::milliseconds timeout) override {
    if (bus_off_->exchange(false)) {
      CanFrame e;
      e.error = true;
      e.id = 0x40;  // CAN_ERR_BUSOFF
      e.dlc = 8;
      return e;
    }
    return real_->Receive(timeout);
  }
  const std::string& interface_name() const override { return real_->interface_name(); }

 private:
  std::unique_ptr<CanPort> real_;
  std::shared_ptr<std::atomic<bool>> bus_off_;
};

TEST_F(CanFixtureTest, BusOffErrorFrameFailsReadsAndWrites) {
  StartNode();
  auto bus_off = std::make_shared<std::atomic<bool>>(false);
  CanFixture fixture(
      settings_, [bus_off](const std::string& ifname, const std::vector<CanFilter>& filters) {
        return std::make_unique<BusOffPort>(SocketCanPortFactory()(ifname, filters), bus_off);
      });
  ASSERT_TRUE(fixture.Connect().ok());
  ASSERT_TRUE(fixture.ReadInputs().ok());
  *bus_off = true;
  const Status s = ReadUntilError(fixture);
  ASSERT_FALSE(s.ok());
  EXPECT_CONTAINS(s.message(), std::string(kInterface) + ": bus-off (error frame 0x00000040");
  ASSERT_TRUE(fixture.Connect().ok()) << "a reconnect after repair recovers";
  EXPECT_TRUE(fixture.ReadInputs().ok());
}

TEST(CanLinkTest, MissingInterfaceIsNamed) {
  try {
    SocketCanPort port("vcan_nope", {}, false);
    FAIL() << "opened an interface that does not exist";
  } catch (const DeviceError& e) {
    EXPECT_CONTAINS(e.what(), "vcan_nope: ");
  }
}

TEST(CanMapTest, DefaultMapMatchesTheReadme) {
  const CanMap m;
  std::string why;
  ASSERT_TRUE(m.IsValid(&why)) << why;
  EXPECT_EQ(m.command_id(), 0x201u);
  EXPECT_EQ(m.status_id(), 0x181u);
  EXPECT_EQ(m.heartbeat_id(), 0x701u);
  EXPECT_EQ(m.Dlc(CanFrameKind::kCommand), 4);  // with station_alive
  EXPECT_EQ(m.Dlc(CanFrameKind::kStatus), 6);
  EXPECT_EQ(m.Dlc(CanFrameKind::kHeartbeat), 2);
  std::uint8_t d[8] = {};
  SetField(d, m.clamp_pressure, 550);
  SetField(d, m.estop_ok, 1);
  EXPECT_EQ(d[3], 0x26);
  EXPECT_EQ(d[4], 0x02);
  EXPECT_EQ(d[0], 0x10);
  EXPECT_EQ(GetField(d, m.clamp_pressure), 550u);
}

TEST(CanMapTest, BadMapsAreNamed) {
  const auto error = [](const nlohmann::json& j) -> std::string {
    try {
      ParseCanMap(j, "/fixture/map");
    } catch (const io::ConfigError& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_EQ(error(R"({"clamped": {"byte": 0, "bit": 1}})"_json),
            "/fixture/map: released: byte 0 bit 1 of the status frame is already used by clamped");
  EXPECT_EQ(error(R"({"clamp_pressure": {"byte": 7}})"_json),
            "/fixture/map: clamp_pressure: byte 7 bit 0 does not fit a 16-bit field in 8 data "
            "bytes");
  EXPECT_EQ(error(R"({"status_base_id": 512})"_json).rfind("/fixture/map: the command, status", 0),
            0u);
  EXPECT_EQ(error(R"({"clamped": {"byte": 9}})"_json)
                .rfind("/fixture/map/clamped/byte: must be "
                       "in 0..7",
                       0),
            0u);
  EXPECT_CONTAINS(error(R"({"clampd": 3})"_json), "/fixture/map/clampd");
  EXPECT_CONTAINS(error(R"({"clampd": 3})"_json), "known: command_base_id");
}

}  // namespace
}  // namespace eol::drivers
