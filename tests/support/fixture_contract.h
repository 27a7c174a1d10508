// The contract of drivers::Fixture (drivers/fixture/fixture.h), one parameterised suite that
// every backend runs (tests/README.md): the sim fixture in-process, and the Modbus and CAN
// fixtures against their emulators over real transports. Each backend is a FixtureBackend:
// given the simulated bench (on a ManualClock), it starts whatever peer it needs and makes
// the driver. The bench is the truth the driver is checked against: what a write did is read
// back from the bench, what the bench shows is read through the driver.
//
// Time: the bench's physics runs on the test's ManualClock, so "the clamp closes after
// clamp_close_s" is stated by advancing the clock, not by sleeping. The transports run in
// real time: a CAN driver sees the bench through status frames sent every 50 ms, so reads
// poll until the expected state arrives (ReadUntil), with a deadline that only bounds a
// broken run and is no pass/fail threshold.
//
// Include this header in exactly one test program per backend group and instantiate it:
//   INSTANTIATE_TEST_SUITE_P(Modbus, FixtureContractTest,
//                            ::testing::Values(ModbusFixtureBackend()), BackendName);
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "drivers/fixture/fixture.h"
#include "drivers/sim/sim_bench.h"
#include "drivers/sim/sim_clock.h"

namespace eol::testing {

// One backend, started against a bench: the driver, and what its errors must name.
class FixtureUnderTest {
 public:
  virtual ~FixtureUnderTest() = default;
  virtual drivers::Fixture& fixture() = 0;
  // Text a Status of this backend must contain to name the device, beyond "fixture '<name>'"
  // (an endpoint, a node and interface, or the simulated controller).
  virtual std::string device() const = 0;
};

struct FixtureBackend {
  std::string name;  // the test name suffix
  std::function<std::unique_ptr<FixtureUnderTest>(std::shared_ptr<drivers::SimBench>)> start;
};

inline std::string BackendName(const ::testing::TestParamInfo<FixtureBackend>& info) {
  return info.param.name;
}
inline void PrintTo(const FixtureBackend& b, std::ostream* os) { *os << b.name; }

class FixtureContractTest : public ::testing::TestWithParam<FixtureBackend> {
 protected:
  using FixtureInputs = drivers::FixtureInputs;
  using FixtureOutput = drivers::FixtureOutput;
  using Lifecycle = drivers::Lifecycle;
  using SimFault = drivers::SimFault;

  void SetUp() override {
    settings_.clamp_close_s = 0.15;
    settings_.clamp_open_s = 0.10;
    settings_.clamp_pressure_bar = 5.5;
    settings_.heartbeat_period_s = 0.2;
    clock_ = std::make_shared<drivers::ManualClock>();
    bench_ = std::make_shared<drivers::SimBench>(settings_, drivers::ManualClock::Of(clock_));
    bench_->LoadPart("CONTRACT-1");
    under_test_ = GetParam().start(bench_);
    ASSERT_NE(under_test_, nullptr);
  }
  void TearDown() override {
    if (under_test_) under_test_->fixture().Disconnect();
    under_test_.reset();  // the driver first, then its peer
  }

  drivers::Fixture& fixture() { return under_test_->fixture(); }
  std::string Prefix() const { return "fixture '" + under_test_->fixture().name() + "': "; }

  // Connects and activates, asserting both.
  void Activate() {
    const drivers::Status c = fixture().Connect();
    ASSERT_TRUE(c.ok()) << c.message();
    const drivers::Status a = fixture().Activate();
    ASSERT_TRUE(a.ok()) << a.message();
  }

  // Reads until `pred` holds; the last read otherwise.
  drivers::StatusOr<FixtureInputs> ReadUntil(
      const std::function<bool(const FixtureInputs&)>& pred) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    for (;;) {
      drivers::StatusOr<FixtureInputs> in = fixture().ReadInputs();
      if (in.ok() && pred(in.value())) return in;
      if (std::chrono::steady_clock::now() > end) return in;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }

  // Reads until a read fails; its status, or ok when none failed.
  drivers::Status ReadUntilError() {
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (std::chrono::steady_clock::now() < end) {
      drivers::StatusOr<FixtureInputs> in = fixture().ReadInputs();
      if (!in.ok()) return in.status();
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return drivers::Status::Ok();
  }

  // Waits for a state of the bench that a peer thread sets (a relay dropping out).
  bool BenchBecomes(const std::function<bool()>& pred) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (!pred()) {
      if (std::chrono::steady_clock::now() > end) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return true;
  }

  drivers::SimBenchSettings settings_;
  std::shared_ptr<drivers::ManualClock> clock_;
  std::shared_ptr<drivers::SimBench> bench_;
  std::unique_ptr<FixtureUnderTest> under_test_;
};

#define EOL_EXPECT_CONTAINS(text, part) \
  EXPECT_NE(std::string(text).find(part), std::string::npos) << "in: " << (text)

// unconfigured -> inactive -> active -> inactive -> finalized, and what each state refuses.
TEST_P(FixtureContractTest, LifecycleAndWhatEachStateRefuses) {
  drivers::Fixture& f = fixture();
  EXPECT_EQ(f.lifecycle(), Lifecycle::kUnconfigured);
  const auto early = f.ReadInputs();
  ASSERT_FALSE(early.ok());
  EXPECT_EQ(early.status().message(), Prefix() + "read inputs: not connected (state unconfigured)");
  EXPECT_FALSE(f.Activate().ok()) << "activated before connecting";

  const drivers::Status c = f.Connect();
  ASSERT_TRUE(c.ok()) << c.message();
  EXPECT_EQ(f.lifecycle(), Lifecycle::kInactive);
  EXPECT_TRUE(f.ReadInputs().ok()) << "inactive is connected and may read";
  const drivers::Status clamp = f.Write(FixtureOutput::kClampCmd, true);
  EXPECT_EQ(clamp.message(), Prefix() + "write clamp_cmd=1 refused in state inactive");
  const drivers::Status excite = f.Write(FixtureOutput::kExcitationEnable, true);
  EXPECT_EQ(excite.message(), Prefix() + "write excitation_enable=1 refused in state inactive");
  const drivers::Status pair = f.SelectPhasePair(drivers::PhasePair::kVW);
  EXPECT_EQ(pair.message(), Prefix() + "select phase pair refused in state inactive");
  EXPECT_FALSE(bench_->output(FixtureOutput::kClampCmd));
  EXPECT_FALSE(bench_->excitation_connected());
  EXPECT_EQ(bench_->phase_pair(), drivers::PhasePair::kUV);

  ASSERT_TRUE(f.Activate().ok());
  EXPECT_EQ(f.lifecycle(), Lifecycle::kActive);
  ASSERT_TRUE(f.WriteAlive(1).ok());  // the controller closes the relay only after one
  ASSERT_TRUE(f.Write(FixtureOutput::kExcitationEnable, true).ok());
  EXPECT_TRUE(bench_->excitation_connected());
  const drivers::Status d = f.Deactivate();
  ASSERT_TRUE(d.ok()) << d.message();
  EXPECT_EQ(f.lifecycle(), Lifecycle::kInactive);
  EXPECT_FALSE(bench_->excitation_connected()) << "deactivating leaves the excitation on";

  f.Disconnect();
  EXPECT_EQ(f.lifecycle(), Lifecycle::kFinalized);
  const auto late = f.ReadInputs();
  ASSERT_FALSE(late.ok());
  EXPECT_EQ(late.status().message(), Prefix() + "read inputs: not connected (state finalized)");
}

// The clamp confirms once clamp_close_s has passed on the bench, not before, with the
// pressure in its window; releasing drops the pressure and confirms after clamp_open_s.
TEST_P(FixtureContractTest, ClampConfirmsAfterItsTravelWithPressureInWindow) {
  Activate();
  auto in = ReadUntil([](const FixtureInputs& i) { return i.released; });
  ASSERT_TRUE(in.ok()) << in.status().message();
  EXPECT_FALSE(in.value().clamped);
  EXPECT_EQ(in.value().clamp_pressure_bar, 0.0);

  ASSERT_TRUE(fixture().Write(FixtureOutput::kClampCmd, true).ok());
  EXPECT_TRUE(bench_->output(FixtureOutput::kClampCmd)) << "a write returns once applied";
  in = ReadUntil([](const FixtureInputs& i) { return !i.released; });
  ASSERT_TRUE(in.ok()) << in.status().message();
  EXPECT_FALSE(in.value().clamped) << "clamped before the clamp travelled";

  clock_->AdvanceSeconds(settings_.clamp_close_s * 0.5);
  in = fixture().ReadInputs();
  ASSERT_TRUE(in.ok()) << in.status().message();
  EXPECT_FALSE(in.value().clamped) << "clamped half way through the travel";

  clock_->AdvanceSeconds(settings_.clamp_close_s * 0.5 + 0.01);
  in = ReadUntil([](const FixtureInputs& i) { return i.clamped; });
  ASSERT_TRUE(in.ok()) << in.status().message();
  ASSERT_TRUE(in.value().clamped) << "not clamped after clamp_close_s";
  EXPECT_FALSE(in.value().released);
  EXPECT_TRUE(in.value().part_present);
  // 5.5 bar with the bench's 0.02 bar ripple and one 0.01-bar count of the wire formats.
  EXPECT_NEAR(in.value().clamp_pressure_bar, settings_.clamp_pressure_bar, 0.02 + 0.01);

  ASSERT_TRUE(fixture().Write(FixtureOutput::kClampCmd, false).ok());
  in = ReadUntil([](const FixtureInputs& i) { return !i.clamped; });
  ASSERT_TRUE(in.ok()) << in.status().message();
  EXPECT_EQ(in.value().clamp_pressure_bar, 0.0);
  EXPECT_FALSE(in.value().released) << "released before the clamp opened";
  clock_->AdvanceSeconds(settings_.clamp_open_s + 0.01);
  in = ReadUntil([](const FixtureInputs& i) { return i.released; });
  ASSERT_TRUE(in.ok()) << in.status().message();
  EXPECT_TRUE(in.value().released) << "not released after clamp_open_s";
}

// Opening the excitation relay is allowed in every connected state, the error state
// included, and the controller reads it back as off.
TEST_P(FixtureContractTest, ExcitationOffIsAlwaysAllowedAndReadsBackOff) {
  drivers::Fixture& f = fixture();
  ASSERT_TRUE(f.Connect().ok());
  EXPECT_FALSE(bench_->excitation_connected()) << "connecting drives excitation off";
  drivers::Status s = f.Write(FixtureOutput::kExcitationEnable, false);
  EXPECT_TRUE(s.ok()) << "inactive: " << s.message();

  ASSERT_TRUE(f.Activate().ok());
  ASSERT_TRUE(f.WriteAlive(1).ok());
  ASSERT_TRUE(f.Write(FixtureOutput::kExcitationEnable, true).ok());
  ASSERT_TRUE(bench_->excitation_connected());
  s = f.Write(FixtureOutput::kExcitationEnable, false);
  EXPECT_TRUE(s.ok()) << "active: " << s.message();
  EXPECT_FALSE(bench_->output(FixtureOutput::kExcitationEnable));

  // Into the error state by a controller that stopped answering, then back on the bus.
  ASSERT_TRUE(f.WriteAlive(2).ok());
  ASSERT_TRUE(f.Write(FixtureOutput::kExcitationEnable, true).ok());
  bench_->InjectFault(SimFault::kStopsAnswering, std::chrono::milliseconds(0), false);
  ASSERT_FALSE(ReadUntilError().ok());
  ASSERT_EQ(f.lifecycle(), Lifecycle::kError);
  bench_->ClearFaults();
  s = f.Write(FixtureOutput::kExcitationEnable, false);
  EXPECT_TRUE(s.ok()) << "error state: " << s.message();
  EXPECT_FALSE(bench_->output(FixtureOutput::kExcitationEnable));
  EXPECT_FALSE(f.Write(FixtureOutput::kExcitationEnable, true).ok())
      << "excitation on accepted in the error state";
  EXPECT_FALSE(bench_->excitation_connected());
}

// The station-alive rule (drivers/fixture/modbus_map.h): the relay stays closed while
// station_alive keeps changing, opens by itself alive_timeout_ms after the last change (the
// same value again is no change), and closes again only when commanded after a fresh one.
// WriteAlive is allowed in every connected state.
TEST_P(FixtureContractTest, RelayDropsAfterAliveTimeoutWithoutAliveChanges) {
  using std::chrono::milliseconds;
  drivers::Fixture& f = fixture();
  EXPECT_FALSE(f.WriteAlive(1).ok()) << "station_alive written before connecting";
  ASSERT_TRUE(f.Connect().ok());
  ASSERT_TRUE(f.WriteAlive(1).ok()) << "inactive";
  EXPECT_EQ(bench_->alive(), std::optional<std::uint16_t>(1));
  ASSERT_TRUE(f.Activate().ok());
  ASSERT_TRUE(f.WriteAlive(2).ok());
  ASSERT_TRUE(f.Write(FixtureOutput::kExcitationEnable, true).ok());
  ASSERT_TRUE(bench_->excitation_connected());
  for (std::uint16_t v = 3; v < 13; ++v) {  // 2 s of changes every 200 ms
    clock_->Advance(milliseconds(200));
    ASSERT_TRUE(f.WriteAlive(v).ok());
    ASSERT_TRUE(bench_->excitation_connected()) << "dropped with station_alive changing, at " << v;
  }
  const auto last_change = clock_->now();
  clock_->Advance(milliseconds(200));
  ASSERT_TRUE(f.WriteAlive(12).ok());  // the same value: no change
  EXPECT_TRUE(bench_->excitation_connected()) << "dropped 200 ms after the last change";
  clock_->Advance(milliseconds(51));
  EXPECT_FALSE(bench_->excitation_connected()) << "closed 251 ms after the last change";
  EXPECT_FALSE(bench_->output(FixtureOutput::kExcitationEnable));
  const auto timeout = milliseconds(static_cast<int>(settings_.alive_timeout_ms));
  EXPECT_EQ(bench_->last_excitation_off(), std::optional(last_change + timeout));

  ASSERT_TRUE(f.Write(FixtureOutput::kExcitationEnable, false).ok());
  ASSERT_TRUE(f.WriteAlive(13).ok());
  EXPECT_FALSE(bench_->excitation_connected()) << "a fresh alive alone closed the relay";
  ASSERT_TRUE(f.Write(FixtureOutput::kExcitationEnable, true).ok());
  EXPECT_TRUE(bench_->excitation_connected()) << "not closed when commanded after a fresh alive";
}

// The interlock latch (modbus_map.h): a door that opened and closed again between two reads
// is reported open by the next read, and only by that one (clear-on-read).
TEST_P(FixtureContractTest, DoorDropBetweenTwoReadsIsLatched) {
  Activate();
  auto in = ReadUntil([](const FixtureInputs& i) { return i.door_closed; });
  ASSERT_TRUE(in.ok()) << in.status().message();
  ASSERT_TRUE(in.value().door_closed);
  bench_->InjectFault(SimFault::kDoorOpens, std::chrono::milliseconds(10), false,
                      std::chrono::milliseconds(20));
  clock_->Advance(std::chrono::milliseconds(100));  // opened at 10 ms, closed at 30 ms
  ASSERT_FALSE(bench_->FaultActive(SimFault::kDoorOpens));
  in = ReadUntil([](const FixtureInputs& i) { return !i.door_closed; });
  ASSERT_TRUE(in.ok()) << in.status().message();
  EXPECT_FALSE(in.value().door_closed) << "a door drop between two reads was lost";
  in = ReadUntil([](const FixtureInputs& i) { return i.door_closed; });
  ASSERT_TRUE(in.ok()) << in.status().message();
  EXPECT_TRUE(in.value().door_closed) << "the latch did not clear on read";
}

TEST_P(FixtureContractTest, PhasePairSelectionReadsBack) {
  Activate();
  for (drivers::PhasePair p :
       {drivers::PhasePair::kVW, drivers::PhasePair::kWU, drivers::PhasePair::kUV}) {
    const drivers::Status s = fixture().SelectPhasePair(p);
    ASSERT_TRUE(s.ok()) << s.message();
    EXPECT_EQ(bench_->phase_pair(), p);
  }
  ASSERT_TRUE(fixture().SelectPhasePair(drivers::PhasePair::kWU).ok());
  ASSERT_TRUE(fixture().Write(FixtureOutput::kExcitationEnable, true).ok());
  EXPECT_EQ(bench_->phase_pair(), drivers::PhasePair::kWU) << "another write moved the pair";
}

// Door, emergency stop and part presence as the bench shows them.
TEST_P(FixtureContractTest, InterlockInputsAreVisible) {
  ASSERT_TRUE(fixture().Connect().ok());
  auto in = ReadUntil([](const FixtureInputs& i) { return i.door_closed && i.estop_ok; });
  ASSERT_TRUE(in.ok()) << in.status().message();
  EXPECT_TRUE(in.value().part_present);

  bench_->InjectFault(SimFault::kDoorOpens, std::chrono::milliseconds(0), false);
  in = ReadUntil([](const FixtureInputs& i) { return !i.door_closed; });
  ASSERT_TRUE(in.ok()) << in.status().message();
  EXPECT_FALSE(in.value().door_closed) << "open door not seen";
  EXPECT_TRUE(in.value().estop_ok);

  bench_->InjectFault(SimFault::kEstop, std::chrono::milliseconds(0), false);
  in = ReadUntil([](const FixtureInputs& i) { return !i.estop_ok; });
  ASSERT_TRUE(in.ok()) << in.status().message();
  EXPECT_FALSE(in.value().estop_ok) << "open emergency-stop chain not seen";
  EXPECT_TRUE(in.value().door_closed);

  bench_->ClearFaults();
  bench_->RemovePart();
  in = ReadUntil([](const FixtureInputs& i) { return !i.part_present; });
  ASSERT_TRUE(in.ok()) << in.status().message();
  EXPECT_FALSE(in.value().part_present) << "removed part still present";
  EXPECT_TRUE(in.value().door_closed && in.value().estop_ok);
}

// The heartbeat stands while the bench's time stands and advances one count per
// heartbeat_period_s of it.
TEST_P(FixtureContractTest, HeartbeatAdvancesWithTheControllersTime) {
  ASSERT_TRUE(fixture().Connect().ok());
  auto first = fixture().ReadInputs();
  ASSERT_TRUE(first.ok()) << first.status().message();
  auto again = fixture().ReadInputs();
  ASSERT_TRUE(again.ok()) << again.status().message();
  EXPECT_EQ(again.value().heartbeat, first.value().heartbeat) << "beat with time standing";

  clock_->AdvanceSeconds(3.25 * settings_.heartbeat_period_s);
  const std::uint32_t h0 = first.value().heartbeat;
  auto later = ReadUntil([&](const FixtureInputs& i) { return i.heartbeat != h0; });
  ASSERT_TRUE(later.ok()) << later.status().message();
  // Counters wrap (CAN: mod 256, Modbus: mod 2^16); three beats is far from either.
  EXPECT_EQ((later.value().heartbeat - h0) & 0xFFu, 3u) << h0 << " -> " << later.value().heartbeat;
}

// A controller that stops answering: reads and writes fail with a Status that names the
// device, the fixture is in the error state, its relay is open once the station tried to
// open it, and Connect recovers once it answers again.
TEST_P(FixtureContractTest, StopsAnsweringIsNamedAndConnectRecovers) {
  Activate();
  ASSERT_TRUE(fixture().Write(FixtureOutput::kExcitationEnable, true).ok());
  bench_->InjectFault(SimFault::kStopsAnswering, std::chrono::milliseconds(0), false);
  const drivers::Status read = ReadUntilError();
  ASSERT_FALSE(read.ok()) << "reads kept succeeding from a silent controller";
  EXPECT_EQ(read.message().rfind(Prefix() + "read inputs: ", 0), 0u) << read.message();
  EOL_EXPECT_CONTAINS(read.message(), under_test_->device());
  EXPECT_EQ(fixture().lifecycle(), Lifecycle::kError);
  EXPECT_FALSE(fixture().Activate().ok()) << "activated from the error state";

  const drivers::Status off = fixture().Deactivate();
  EXPECT_FALSE(off.ok()) << "switching off a silent controller reported success";
  EOL_EXPECT_CONTAINS(off.message(), under_test_->device());
  EXPECT_TRUE(BenchBecomes([&] { return !bench_->excitation_connected(); }))
      << "the excitation relay stayed closed";

  bench_->ClearFaults();
  const drivers::Status back = fixture().Connect();
  ASSERT_TRUE(back.ok()) << back.message();
  EXPECT_EQ(fixture().lifecycle(), Lifecycle::kInactive);
  const auto in = ReadUntil([](const FixtureInputs& i) { return i.part_present; });
  ASSERT_TRUE(in.ok()) << in.status().message();
}

// The lamps move nothing: they may be driven whenever connected, and read back.
TEST_P(FixtureContractTest, LampsAreDrivenInEveryConnectedState) {
  ASSERT_TRUE(fixture().Connect().ok());
  ASSERT_TRUE(fixture().Write(FixtureOutput::kLampPass, true).ok());
  EXPECT_TRUE(bench_->output(FixtureOutput::kLampPass));
  EXPECT_FALSE(bench_->output(FixtureOutput::kLampFail));
  ASSERT_TRUE(fixture().Activate().ok());
  ASSERT_TRUE(fixture().Write(FixtureOutput::kLampFail, true).ok());
  EXPECT_TRUE(bench_->output(FixtureOutput::kLampPass));
  EXPECT_TRUE(bench_->output(FixtureOutput::kLampFail));
  ASSERT_TRUE(fixture().Write(FixtureOutput::kLampPass, false).ok());
  EXPECT_FALSE(bench_->output(FixtureOutput::kLampPass));
  EXPECT_TRUE(bench_->output(FixtureOutput::kLampFail));
  EXPECT_FALSE(bench_->excitation_connected()) << "a lamp write closed the relay";
  EXPECT_FALSE(bench_->output(FixtureOutput::kClampCmd)) << "a lamp write moved the clamp";
}

}  // namespace eol::testing
