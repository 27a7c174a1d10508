// The excitation watchdog (station/daemon/safety.h) through the sequencer, on the simulated bench
// with its controller rules (station_alive, latched interlocks) and a real SQLite file: a
// stall of the watchdog's loop ends ERROR "watchdog stalled" and leaves its gap in the
// record, never PASS; the controller opens the relay by itself while the station is stuck;
// a door drop shorter than the watchdog's period is still seen.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <thread>

#include "../support/child_process.h"
#include "../support/glitch_proxy.h"
#include "../support/wait_until.h"
#include "drivers/emulators/modbus_fixture_server.h"
#include "drivers/fixture/modbus_fixture.h"
#include "drivers/sim/sim_bench.h"
#include "drivers/sim/sim_daq.h"
#include "station/daemon/reason_cause.h"
#include "station/daemon/safety.h"
#include "station/daemon/sequencer.h"

namespace eol::station {
namespace {

using analysis::Outcome;
using drivers::FixtureOutput;
using drivers::SimFault;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

// The interlock rule on the clamp pressure holds the pressure inside its window: a reading
// that is not a number (a failed conversion, a broken sensor model) is a fault, never a pass.
TEST(InterlockRules, APressureThatIsNotANumberIsAFault) {
  Recipe recipe;  // window 4.5..6.5 bar
  drivers::FixtureInputs in;
  in.estop_ok = in.door_closed = in.part_present = in.clamped = true;
  in.clamp_pressure_bar = 5.0;
  EXPECT_TRUE(FindInterlockFault(in, recipe, true).text.empty());
  for (double p : {std::nan(""), 1.0, 7.0, std::numeric_limits<double>::infinity()}) {
    in.clamp_pressure_bar = p;
    const InterlockFinding f = FindInterlockFault(in, recipe, true);
    EXPECT_EQ(f.cause, cause::kClampPressure) << p;
    EXPECT_NE(f.text.find("clamp pressure"), std::string::npos) << f.text;
  }
}

// The sim fixture with a hook that holds one read during excitation, as a frozen station
// (or a stuck bus) would: the read blocks for `stall` under the fixture's lock, so nothing
// else reaches the fixture meanwhile, station_alive included.
class StallingFixture final : public drivers::Fixture {
 public:
  explicit StallingFixture(std::shared_ptr<drivers::SimBench> bench)
      : Fixture("stalling-sim"), bench_(std::move(bench)) {}
  // The first read after the relay has been closed for `after` blocks for `stall`.
  void StallOnce(std::chrono::milliseconds after, std::chrono::milliseconds stall) {
    after_ = after;
    stall_ = stall;
    armed_ = true;
  }
  std::optional<Clock::time_point> stalled_at() const { return stalled_at_; }
  int alive_writes() const { return alive_writes_.load(); }

 protected:
  void DoConnect() override {}
  void DoDisconnect() override {}
  drivers::FixtureInputs DoReadInputs() override {
    if (armed_ && closed_at_ && Clock::now() - *closed_at_ >= after_) {
      armed_ = false;
      stalled_at_ = Clock::now();
      std::this_thread::sleep_for(stall_);
    }
    return bench_->ReadInputs();
  }
  void DoWrite(FixtureOutput output, bool on) override {
    bench_->Write(output, on);
    if (output == FixtureOutput::kExcitationEnable && on && !closed_at_) closed_at_ = Clock::now();
  }
  void DoSelectPhasePair(drivers::PhasePair pair) override { bench_->SelectPhasePair(pair); }
  void DoWriteAlive(std::uint16_t value) override {
    bench_->WriteAlive(value);
    ++alive_writes_;
  }

 private:
  std::shared_ptr<drivers::SimBench> bench_;
  bool armed_ = false;
  std::chrono::milliseconds after_{0}, stall_{0};
  std::optional<Clock::time_point> closed_at_, stalled_at_;
  std::atomic<int> alive_writes_{0};
};

class WatchdogTest : public ::testing::Test {
 protected:
  void Build(const SafetyOptions& safety = {}) {
    drivers::SimBenchSettings bench_settings;
    bench_settings.clamp_close_s = 0.05;
    bench_settings.clamp_open_s = 0.03;
    bench_ = std::make_shared<drivers::SimBench>(bench_settings);
    fixture_ = std::make_unique<StallingFixture>(bench_);
    drivers::SimDaqSettings daq_settings;
    daq_settings.time_scale = 1.0;  // real time: the stall lands inside the excitation
    daq_ = std::make_unique<drivers::SimDaq>(bench_, daq_settings);
    ASSERT_TRUE(fixture_->Connect().ok());
    ASSERT_TRUE(daq_->Connect().ok());
    store_ = db::Store::Open(dir_ / "eol.sqlite");
    recipe_ = LoadRecipe(std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json");
    board_ = std::make_unique<StatusBoard>("test");
    SequencerOptions o;
    o.station_id = "test";
    o.safety = safety;
    sequencer_ = std::make_unique<Sequencer>(*fixture_, *daq_, *store_,
                                             std::make_shared<const Recipe>(recipe_), *board_, o);
  }

  db::TestRecord Test(const std::string& serial) {
    bench_->LoadUnit(analysis::DrawUnit(bench_->settings().population, serial, false));
    return sequencer_->RunTest(serial);
  }

  static std::string FirstReason(const db::TestRecord& r) {
    return r.reasons.empty() ? "" : r.reasons.front().text;
  }

  eol::testing::TempDir dir_;
  std::shared_ptr<drivers::SimBench> bench_;
  std::unique_ptr<StallingFixture> fixture_;
  std::unique_ptr<drivers::Daq> daq_;
  std::unique_ptr<db::Store> store_;
  Recipe recipe_;
  std::unique_ptr<StatusBoard> board_;
  std::unique_ptr<Sequencer> sequencer_;
};

TEST(ReactionLimitTest, DefaultIsFourPeriodsAndAtLeast100Ms) {
  SafetyOptions s;
  EXPECT_EQ(ReactionLimitMs(s), 100.0);  // 5 ms period
  s.watchdog_period_ms = 40;
  EXPECT_EQ(ReactionLimitMs(s), 160.0);
  s.watchdog_reaction_ms = 70;
  EXPECT_EQ(ReactionLimitMs(s), 70.0);
}

// A read held for 1.5 s inside the excitation: ERROR "watchdog stalled", the gap in the
// record, and the controller opened the relay within its alive timeout while the station
// was stuck (no alive change got through).
TEST_F(WatchdogTest, StallOfTheWatchdogIsErrorNeverPassAndLeavesItsGapInTheRecord) {
  Build();
  fixture_->StallOnce(300ms, 1500ms);
  const db::TestRecord r = Test("STALL-1");
  ASSERT_EQ(r.outcome, Outcome::kError) << FirstReason(r);
  EXPECT_NE(FirstReason(r).find("watchdog stalled"), std::string::npos) << FirstReason(r);
  EXPECT_NE(FirstReason(r).find("(limit 100 ms"), std::string::npos) << FirstReason(r);
  ASSERT_TRUE(r.conditions.watchdog_max_gap_ms.has_value());
  EXPECT_GE(*r.conditions.watchdog_max_gap_ms, 1400.0);
  const auto stored = store_->Test(r.id);
  ASSERT_TRUE(stored);
  EXPECT_EQ(stored->outcome, Outcome::kError);
  EXPECT_GE(stored->conditions.watchdog_max_gap_ms.value(), 1400.0);
  // The controller, not the station, opened the relay: within the alive timeout (250 ms)
  // of the last alive change, which came at most one alive period before the stall.
  ASSERT_TRUE(fixture_->stalled_at() && bench_->last_excitation_off());
  const double off_ms = std::chrono::duration<double, std::milli>(*bench_->last_excitation_off() -
                                                                  *fixture_->stalled_at())
                            .count();
  EXPECT_LE(off_ms, 250.0) << "relay still closed " << off_ms << " ms into the stall";
  EXPECT_GE(off_ms, 250.0 - 50.0 - 20.0);
  EXPECT_FALSE(bench_->excitation_connected());
}

// Without a stall the loop's longest gap is recorded too, below the limit, and the test
// passes: the trace is there for every test.
TEST_F(WatchdogTest, HealthyRunRecordsItsLongestGapBelowTheLimit) {
  Build();
  const db::TestRecord r = Test("GAP-OK");
  ASSERT_EQ(r.outcome, Outcome::kPass) << FirstReason(r);
  ASSERT_TRUE(r.conditions.watchdog_max_gap_ms.has_value());
  EXPECT_LT(*r.conditions.watchdog_max_gap_ms, 100.0);
  EXPECT_GT(*r.conditions.watchdog_max_gap_ms, 0.0);
}

// A door that opens for 10 ms between two reads 50 ms apart: without the controller's
// latch most such drops are never read; with it every one is.
TEST_F(WatchdogTest, DoorDropBetweenTwoWatchdogReadsIsSeenThroughTheLatch) {
  SafetyOptions safety;
  safety.watchdog_period_ms = 50;
  safety.watchdog_reaction_ms = 1000;
  Build(safety);
  bench_->InjectFault(SimFault::kDoorOpens, 400ms, true, 10ms);
  const db::TestRecord r = Test("DOOR-BLINK");
  ASSERT_EQ(r.outcome, Outcome::kError) << FirstReason(r);
  EXPECT_NE(FirstReason(r).find("door open"), std::string::npos) << FirstReason(r);
  EXPECT_FALSE(bench_->excitation_connected());
}

// The alive rule through the watchdog's own writer: the relay stays closed for the whole
// excitation (seconds, against a 250 ms alive timeout) because station_alive keeps changing,
// written every 50 ms: dozens of writes, not just the two before the relay closed. A second
// sequencer (a restarted daemon, its counter anywhere) closes the relay again.
TEST_F(WatchdogTest, StationAliveKeepsTheRelayClosedThroughExcitation) {
  Build();
  const db::TestRecord r = Test("ALIVE-1");
  ASSERT_EQ(r.outcome, Outcome::kPass) << FirstReason(r);
  EXPECT_GT(fixture_->alive_writes(), 20);
  ASSERT_TRUE(bench_->last_excitation_off().has_value());
  SequencerOptions o;
  o.station_id = "test";
  sequencer_ = std::make_unique<Sequencer>(*fixture_, *daq_, *store_,
                                           std::make_shared<const Recipe>(recipe_), *board_, o);
  const db::TestRecord again = Test("ALIVE-2");
  EXPECT_EQ(again.outcome, Outcome::kPass) << FirstReason(again);
}

// Through the real Modbus driver and the emulator on 127.0.0.1: a reply spoiled on the wire
// while the stator is excited (another unit id, another function) ends the test ERROR with
// the cause named, the request not retried, and the relay open.
class WatchdogModbusTest : public ::testing::TestWithParam<eol::testing::GlitchProxy::Glitch> {};

TEST_P(WatchdogModbusTest, SpoiledReplyInExcitationIsErrorWithoutRetryAndTheRelayOff) {
  eol::testing::TempDir dir;
  drivers::SimBenchSettings bs;
  bs.clamp_close_s = 0.05;
  bs.clamp_open_s = 0.03;
  auto bench = std::make_shared<drivers::SimBench>(bs);
  drivers::ModbusFixtureServerSettings ss;
  ss.link.port = 0;
  drivers::ModbusFixtureServer server(bench, ss);
  ASSERT_TRUE(server.Start().ok());
  eol::testing::GlitchProxy proxy(server.port());
  drivers::ModbusFixtureSettings cs;
  cs.link.port = proxy.port();
  cs.response_timeout_ms = 100;
  drivers::ModbusFixture fixture(cs);
  drivers::SimDaqSettings ds;
  ds.time_scale = 1.0;
  drivers::SimDaq daq(bench, ds);
  ASSERT_TRUE(fixture.Connect().ok());
  ASSERT_TRUE(daq.Connect().ok());
  auto store = db::Store::Open(dir / "eol.sqlite");
  StatusBoard board("test");
  SequencerOptions o;
  o.station_id = "test";
  Sequencer seq(fixture, daq, *store,
                std::make_shared<const Recipe>(
                    LoadRecipe(std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json")),
                board, o);
  std::thread arm([&] {  // inside the excitation: after the watchdog's first reads in it
    using eol::testing::WaitUntil;
    if (!WaitUntil([&] { return bench->excitation_connected(); })) return;
    const int before = proxy.requests();
    if (WaitUntil([&] { return proxy.requests() >= before + 10; })) proxy.Arm(GetParam());
  });
  bench->LoadUnit(analysis::DrawUnit(bench->settings().population, "GLITCH-1", false));
  const db::TestRecord r = seq.RunTest("GLITCH-1");
  arm.join();
  ASSERT_EQ(r.outcome, Outcome::kError);
  const std::string why = r.reasons.empty() ? "" : r.reasons.front().text;
  EXPECT_NE(why.find("interlock lost during excitation"), std::string::npos) << why;
  EXPECT_NE(why.find(GetParam() == eol::testing::GlitchProxy::Glitch::kForeignUnit
                         ? "reply from unit 7 to a request for unit 1"
                         : "malformed reply"),
            std::string::npos)
      << why;
  EXPECT_NE(why.find("attempt 1, timeout 100 ms, in excitation: not retried"), std::string::npos)
      << why;
  EXPECT_FALSE(proxy.armed()) << "the glitch never reached the driver";
  EXPECT_TRUE(bench->last_excitation_off().has_value());
  EXPECT_FALSE(bench->excitation_connected());
  fixture.Disconnect();
  server.Stop();
}

INSTANTIATE_TEST_SUITE_P(Replies, WatchdogModbusTest,
                         ::testing::Values(eol::testing::GlitchProxy::Glitch::kForeignUnit,
                                           eol::testing::GlitchProxy::Glitch::kWrongFunction),
                         [](const auto& info) {
                           return info.param == eol::testing::GlitchProxy::Glitch::kForeignUnit
                                      ? std::string("ForeignUnit")
                                      : std::string("WrongFunction");
                         });

}  // namespace
}  // namespace eol::station
