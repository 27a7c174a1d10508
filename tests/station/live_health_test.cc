// Issue 36, live health: the station looks at the fixture controller while idle, and "ready"
// follows a controller that stops and returns within one health period, without a scan. Real
// components: the Modbus TCP fixture emulator on 127.0.0.1 (stopped and restarted on its
// port), the station's own Modbus driver, a real SQLite store. The probe's own logic runs on
// a manual clock; the idle station runs on the steady clock and is watched through its board
// with bounded waits.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <set>
#include <string>
#include <thread>

#include "drivers/emulators/modbus_fixture_server.h"
#include "drivers/fixture/modbus_fixture.h"
#include "drivers/sim/sim_clock.h"
#include "drivers/sim/sim_fixture.h"
#include "station/daemon/health.h"
#include "station/daemon/station.h"
#include "station/daemon/status_board.h"
#include "tests/support/child_process.h"
#include "tests/support/wait_until.h"

namespace eol::station {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

TEST(NotReadyCauses, EachHasOneStableCodeAndAnOperatorText) {
  std::set<std::string> codes;
  for (NotReadyCause c : kNotReadyCauses) {
    const std::string code = Code(c);
    EXPECT_TRUE(codes.insert(code).second) << code << " is used twice";
    EXPECT_EQ(code.find_first_not_of("abcdefghijklmnopqrstuvwxyz_"), std::string::npos) << code;
    EXPECT_NE(code, "unknown");
    const std::string text = OperatorText(c);
    EXPECT_GT(text.size(), 10u) << code;
    EXPECT_NE(text.find(" - "), std::string::npos) << code << ": what, then what to do";
    ASSERT_TRUE(ParseNotReadyCode(code).has_value()) << code;
    EXPECT_EQ(*ParseNotReadyCode(code), c);
  }
  // Every enumerator is listed (the last one's value + 1 is the count).
  EXPECT_EQ(codes.size(), static_cast<std::size_t>(NotReadyCause::kStoreLostVerdicts) + 1);
  EXPECT_EQ(Code(NotReadyCause::kFixtureUnreachable), std::string("fixture_unreachable"));
  EXPECT_FALSE(ParseNotReadyCode("fixture_gone").has_value());
}

TEST(StatusBoardReadiness, CausesAreTypedOrderedAndEachChangeIsAnEvent) {
  StatusBoard board("b");
  EXPECT_EQ(board.Snapshot()["not_ready_code"], "drivers_not_connected");
  board.ClearCause(NotReadyCause::kDriversNotConnected);
  EXPECT_TRUE(board.Snapshot()["ready"].get<bool>());
  EXPECT_EQ(board.Snapshot()["not_ready_code"], "");
  const std::uint64_t before = board.last_event();
  board.SetCause(NotReadyCause::kStoreWriteFailed, "store write failed: disk full");
  board.SetCause(NotReadyCause::kFixtureUnreachable, "fixture unavailable: Connection refused");
  board.SetCause(NotReadyCause::kFixtureUnreachable, "fixture unavailable: Connection refused");
  const nlohmann::json s = board.Snapshot();
  EXPECT_FALSE(s["ready"].get<bool>());
  // The fixture outranks the store: its code and words are the headline.
  EXPECT_EQ(s["not_ready_code"], "fixture_unreachable");
  EXPECT_EQ(s["not_ready_text"], OperatorText(NotReadyCause::kFixtureUnreachable));
  EXPECT_EQ(s["not_ready_reason"],
            "fixture unavailable: Connection refused; store write failed: disk full");
  ASSERT_EQ(s["not_ready"].size(), 2u);
  EXPECT_EQ(s["not_ready"][1]["code"], "store_write_failed");
  EXPECT_EQ(board.last_event(), before + 2) << "an unchanged cause is no event";
  const auto events = board.EventsAfter(before, 0ms);
  EXPECT_EQ(events.back().second["type"], "readiness");
  EXPECT_EQ(events.back().second["not_ready_code"], "fixture_unreachable");
  board.ClearCause(NotReadyCause::kFixtureUnreachable);
  board.ClearCause(NotReadyCause::kStoreWriteFailed);
  EXPECT_TRUE(board.Snapshot()["ready"].get<bool>());
  EXPECT_EQ(board.Snapshot()["not_ready_reason"], "");
}

TEST(StatusBoardReadiness, TheNextVerdictClearsAStaleMessage) {
  StatusBoard board("b");
  board.SetMessage("fixture 'modbus': read inputs: Connection refused");
  const std::uint64_t before = board.last_event();
  db::TestRecord r;
  r.serial = "AFTER-1";
  r.outcome = analysis::Outcome::kPass;
  board.OnVerdict(r);
  EXPECT_EQ(board.Snapshot()["message"], "");
  const auto events = board.EventsAfter(before, 0ms);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].second["type"], "verdict");
  EXPECT_EQ(events[1].second, (nlohmann::json{{"type", "message"}, {"message", ""}}));
}

// The causes a probe found, by code.
std::set<std::string> Codes(const std::vector<FixtureProbe::Finding>& found) {
  std::set<std::string> codes;
  for (const auto& f : found) codes.insert(Code(f.first));
  return codes;
}

// The heartbeat and the emergency stop on a manual clock: the simulated controller's counter
// stops, and only a look later than heartbeat_timeout after its last change calls it frozen.
TEST(FixtureProbe, SeesAFrozenHeartbeatAndAnOpenEstopOnAManualClock) {
  auto clock = std::make_shared<drivers::ManualClock>();
  auto bench = std::make_shared<drivers::SimBench>(drivers::SimBenchSettings{},
                                                   drivers::ManualClock::Of(clock));
  drivers::SimFixture fixture(bench);
  FixtureProbe probe(fixture, 1500ms);
  EXPECT_TRUE(probe.Look(clock->now()).empty());
  EXPECT_EQ(fixture.lifecycle(), drivers::Lifecycle::kInactive) << "the probe connects";
  clock->Advance(300ms);
  EXPECT_TRUE(probe.Look(clock->now()).empty());
  bench->InjectFault(drivers::SimFault::kHeartbeatFreezes, 0ms, /*on_excitation=*/false);
  clock->Advance(1400ms);  // the beat's last change is at most 200 ms older than the fault
  EXPECT_TRUE(probe.Look(clock->now()).empty()) << "not yet past the timeout";
  clock->Advance(400ms);
  const auto frozen = probe.Look(clock->now());
  EXPECT_EQ(Codes(frozen), (std::set<std::string>{"fixture_heartbeat_frozen"}));
  ASSERT_FALSE(frozen.empty());
  EXPECT_NE(frozen[0].second.find("limit 1500 ms"), std::string::npos) << frozen[0].second;
  bench->ClearFaults();
  clock->Advance(300ms);
  EXPECT_TRUE(probe.Look(clock->now()).empty()) << "a moving counter is alive again";
  bench->InjectFault(drivers::SimFault::kEstop, 0ms, /*on_excitation=*/false);
  clock->Advance(200ms);
  EXPECT_EQ(Codes(probe.Look(clock->now())), (std::set<std::string>{"estop_open"}));
  // It only looked: nothing was commanded.
  EXPECT_FALSE(bench->output(drivers::FixtureOutput::kClampCmd));
  EXPECT_FALSE(bench->output(drivers::FixtureOutput::kExcitationEnable));
}

drivers::ModbusFixtureServerSettings EmulatorOn(int port) {
  drivers::ModbusFixtureServerSettings s;
  s.link.port = port;
  return s;
}

// The real emulator stopped and started again on its port, the station's Modbus driver.
TEST(FixtureProbe, FollowsAModbusControllerThatStopsAndReturns) {
  auto bench = std::make_shared<drivers::SimBench>(drivers::SimBenchSettings{});
  auto server = std::make_unique<drivers::ModbusFixtureServer>(bench, EmulatorOn(0));
  ASSERT_TRUE(server->Start().ok());
  const int port = server->port();
  drivers::ModbusFixtureSettings c;
  c.link.host = "127.0.0.1";
  c.link.port = port;
  drivers::ModbusFixture fixture(c);
  FixtureProbe probe(fixture, 1500ms);
  EXPECT_TRUE(probe.Look(Clock::now()).empty());
  server.reset();  // the controller is gone
  const auto lost = probe.Look(Clock::now());
  EXPECT_EQ(Codes(lost), (std::set<std::string>{"fixture_unreachable"}));
  ASSERT_FALSE(lost.empty());
  EXPECT_NE(lost[0].second.find("127.0.0.1:" + std::to_string(port)), std::string::npos)
      << lost[0].second;
  EXPECT_EQ(Codes(probe.Look(Clock::now())), (std::set<std::string>{"fixture_unreachable"}))
      << "still gone: the reconnect fails too";
  server = std::make_unique<drivers::ModbusFixtureServer>(bench, EmulatorOn(port));
  ASSERT_TRUE(server->Start().ok());
  EXPECT_TRUE(probe.Look(Clock::now()).empty()) << "back: reconnected and read";
}

// A station whose fixture is the Modbus emulator (sharing the simulated bench with the sim
// DAQ, as the demo does), serving as the daemon does.
class IdleStation : public ::testing::Test {
 protected:
  static constexpr int kPeriodMs = 300;

  void SetUp() override {
    bench_ = std::make_shared<drivers::SimBench>(drivers::SimBenchSettings{});
    server_ = std::make_unique<drivers::ModbusFixtureServer>(bench_, EmulatorOn(0));
    ASSERT_TRUE(server_->Start().ok());
    port_ = server_->port();
    const nlohmann::json config = {
        {"station_id", "health"},
        {"recipe", std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json"},
        {"db", dir_ / "s.sqlite"},
        {"fixture", {{"driver", "modbus-tcp"}, {"host", "127.0.0.1"}, {"port", port_}}},
        {"daq", {{"driver", "sim"}}},
        {"health", {{"period_ms", kPeriodMs}}}};
    StationConfig parsed = ParseStationConfig(config, "t", "");
    drivers::DriverSet drivers = drivers::MakeDrivers(parsed.drivers, bench_);
    station_ = std::make_unique<Station>(std::move(parsed), std::move(drivers));
    serve_ = std::thread([this] { station_->Serve(); });
  }
  void TearDown() override {
    if (station_) station_->RequestStop("test over");
    if (serve_.joinable()) serve_.join();
  }
  // Milliseconds until ready() is `want`, polled every 20 ms; -1 after 10 s.
  long MsUntilReady(bool want) {
    const auto t0 = Clock::now();
    if (!eol::testing::WaitUntil([&] { return station_->ready() == want; }, 10s)) return -1;
    return std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - t0).count();
  }

  eol::testing::TempDir dir_;
  std::shared_ptr<drivers::SimBench> bench_;
  std::unique_ptr<drivers::ModbusFixtureServer> server_;
  int port_ = 0;
  std::unique_ptr<Station> station_;
  std::thread serve_;
};

TEST_F(IdleStation, ReadyFollowsTheControllerWithinOnePeriodWithoutAScan) {
  ASSERT_TRUE(station_->ready()) << station_->board().Snapshot().dump();
  // One period plus one failed read (a refused connection: 3 attempts, 150 ms of back-off),
  // plus room for a loaded machine.
  const long bound_ms = kPeriodMs + 700;

  server_.reset();  // the controller dies
  const long lost_ms = MsUntilReady(false);
  const nlohmann::json lost = station_->board().Snapshot();
  EXPECT_GE(lost_ms, 0) << "ready stayed true: " << lost.dump();
  EXPECT_LE(lost_ms, bound_ms);
  EXPECT_EQ(lost["not_ready_code"], "fixture_unreachable") << lost.dump();
  EXPECT_EQ(lost["not_ready_text"], "Fixture controller not answering - call maintenance");
  EXPECT_NE(lost["not_ready_reason"].get<std::string>().find(std::to_string(port_)),
            std::string::npos)
      << lost["not_ready_reason"];

  server_ = std::make_unique<drivers::ModbusFixtureServer>(bench_, EmulatorOn(port_));
  ASSERT_TRUE(server_->Start().ok());
  const long back_ms = MsUntilReady(true);
  const nlohmann::json back = station_->board().Snapshot();
  EXPECT_GE(back_ms, 0) << "ready stayed false: " << back.dump();
  EXPECT_LE(back_ms, bound_ms);
  EXPECT_EQ(back["not_ready_code"], "");
  std::printf(
      "health period %d ms: not ready %ld ms after the controller stopped, ready %ld ms "
      "after it returned\n",
      kPeriodMs, lost_ms, back_ms);

  // No scan: no test ran, nothing was stored, nothing was clamped or excited.
  EXPECT_EQ(back["state"], "idle");
  EXPECT_TRUE(back["last"].is_null());
  EXPECT_TRUE(station_->store().Tests(db::TestQuery{}).empty());
  EXPECT_FALSE(bench_->output(drivers::FixtureOutput::kClampCmd));
  EXPECT_FALSE(bench_->output(drivers::FixtureOutput::kExcitationEnable));
}

// The look waits for no test: a test in flight holds the fixture, and a look never runs
// beside it (a controller lost during a test is the test's ERROR, and the look after it
// raises the cause).
TEST_F(IdleStation, ATestAfterTheControllerReturnedRunsAndTheLookResumes) {
  server_.reset();
  ASSERT_GE(MsUntilReady(false), 0);
  server_ = std::make_unique<drivers::ModbusFixtureServer>(bench_, EmulatorOn(port_));
  ASSERT_TRUE(server_->Start().ok());
  ASSERT_GE(MsUntilReady(true), 0);
  std::string why;
  ASSERT_TRUE(station_->Enqueue("HEALTH-1", &why)) << why;
  ASSERT_TRUE(eol::testing::WaitUntil(
      [&] { return station_->board().Snapshot()["last"].is_object(); }, 60s));
  const nlohmann::json s = station_->board().Snapshot();
  EXPECT_EQ(s["last"]["serial"], "HEALTH-1");
  EXPECT_NE(s["last"]["outcome"], "ERROR") << s["last"].dump();
  EXPECT_TRUE(station_->ready()) << s.dump();
  server_.reset();
  EXPECT_GE(MsUntilReady(false), 0) << "the look resumed after the test";
}

}  // namespace
}  // namespace eol::station
