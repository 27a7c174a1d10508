// The simulated test bench: the physical world behind the sim drivers and `eol fixture-sim`.
//
// It holds the part in the fixture (a simulated motor drawn from a population), the clamp
// with realistic timing and pressure, the door, the emergency stop, the excitation relay,
// the phase-pair relay, the lamps and the controller heartbeat, plus injectable faults.
// The sim fixture driver reads and writes it directly; `eol fixture-sim` serves it over
// Modbus/CAN; the sim DAQ asks it which motor is connected and whether the relay is closed.
// Thread-safe. Its time comes from a SimClock (sim_clock.h): the steady clock unless a test
// passes a ManualClock, and every time point it reports is on that clock.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "analysis/sim/population.h"
#include "drivers/fixture/fixture.h"
#include "drivers/sim/sim_clock.h"

namespace eol::drivers {

// A reference part kept at the station for self-checks: the population's nominal unit (no
// production spread), good or with the soft magnet bond (station/daemon/self_check.h).
struct SimMaster {
  std::string serial;
  bool defective = false;
};

struct SimBenchSettings {
  analysis::MotorPopulation population;
  double clamp_close_s = 0.15;      // command to clamped sensor
  double clamp_open_s = 0.10;       // command to released sensor
  double clamp_pressure_bar = 5.5;  // steady pressure when closed
  double heartbeat_period_s = 0.2;
  bool load_part_on_serial = true;  // the simulated operator loads a part per serial
  std::vector<SimMaster> masters;   // LoadPart of one of these serials loads that master
  // Fixture wear: each part loaded softens the fixture spring by this share of its new
  // stiffness (k_fixture x (1 - wear n) after n parts, at least 5 %), which lowers f0 slowly.
  double fixture_wear_per_test = 0.0;
  // The clamp's pressure from part to part (the regulator and the seat: standard deviation,
  // bar; 0 keeps every part at clamp_pressure_bar) and what it does to the fixture spring: a
  // friction clamp's contact stiffness grows with the force, k_fixture ~ p^exponent (Hertz:
  // 1/3). A production part's pressure is drawn from its serial (clipped to +-20 %), its
  // fixture spring scaled by (p / clamp_pressure_bar)^exponent, and the clamp reads p; masters
  // and LoadUnit parts sit at clamp_pressure_bar. This is what teach's pressure-normalised
  // resonance (analysis/qc/f0_pressure.h) takes out.
  double clamp_pressure_spread_bar = 0.0;
  double fixture_pressure_exponent = 1.0 / 3.0;
  // The controller's station-alive rule (drivers/fixture/modbus_map.h): the excitation relay
  // closes, and stays closed, only while the station's alive value changed within this
  // time; 0 switches the rule off (a controller not programmed for it).
  double alive_timeout_ms = 250.0;
};

enum class SimFault {
  kStopsAnswering,  // every fixture call fails (controller off the bus)
  kClampDrops,      // clamped sensor drops, pressure falls to 0
  kPressureLow,     // pressure falls to 1 bar (out of any sane window)
  kDoorOpens,
  kEstop,  // emergency-stop chain opens
  kHeartbeatFreezes,
  kDaqFails,     // the acquisition device fails mid-stream
  kClampSticks,  // after an open command the released sensor never comes on
};
// Every simulated fault, in the order the CLIs list them.
inline constexpr std::array<SimFault, 8> kSimFaults = {
    SimFault::kStopsAnswering, SimFault::kClampDrops, SimFault::kPressureLow,
    SimFault::kDoorOpens,      SimFault::kEstop,      SimFault::kHeartbeatFreezes,
    SimFault::kDaqFails,       SimFault::kClampSticks};
const char* ToString(SimFault f);
std::optional<SimFault> ParseSimFault(const std::string& s);

// The latched interlock inputs, each with its own clear-on-read latch.
enum class SimLatch { kClamped = 0, kDoorClosed, kEstopOk, kClampPressure };
inline constexpr int kSimLatchCount = 4;

class SimBench {
 public:
  using Clock = std::chrono::steady_clock;
  explicit SimBench(SimBenchSettings settings, SimClock now = SteadySimClock());

  const SimBenchSettings& settings() const { return settings_; }

  // The simulated operator puts a part in (drawn from the population by serial, or the master
  // of that serial) and takes it out. A new part resets nothing else but wears the fixture.
  void LoadPart(const std::string& serial);
  void LoadUnit(const analysis::SimUnit& unit);
  void RemovePart();
  std::optional<analysis::SimUnit> part() const;

  // Fixture side. ReadInputs throws DeviceError while kStopsAnswering is active.
  // Interlock latch (the controller's required behaviour, modbus_map.h): a drop of
  // door_closed, estop_ok or clamped, or clamp pressure out of its steady value, that
  // happened at any time since the previous ReadInputs is reported by this one even when
  // it has gone again (clear-on-read). PeekInputs shows the same without clearing the latches
  // (an emulator's refresh, another observer); ClearLatch clears one (an emulator, when the
  // station's read request covered that signal).
  FixtureInputs ReadInputs();
  FixtureInputs PeekInputs() const;
  // Clears one as of `as_of` (taken before the reply was built, so that a drop after it is
  // reported again rather than lost).
  void ClearLatch(SimLatch latch, Clock::time_point as_of);
  // The bench's clock.
  Clock::time_point now() const { return now_(); }
  // The station's alive value (station_alive). A value other than the last one received is
  // a change; it keeps a closed relay closed for alive_timeout_ms and lets an excitation
  // command close it.
  void WriteAlive(std::uint16_t value);
  std::optional<std::uint16_t> alive() const;
  void Write(FixtureOutput output, bool on);
  void SelectPhasePair(PhasePair pair);
  bool output(FixtureOutput o) const;
  PhasePair phase_pair() const;
  // True while the relay connects the amplifier to the motor: commanded on and not yet cut.
  // Every observer of the relay (this, output(kExcitationEnable), ReadInputs, Write)
  // first applies the alive rule at the bench's now: a relay whose alive change is older
  // than alive_timeout_ms is open, opened at that change + alive_timeout_ms.
  bool excitation_connected() const;
  // When the excitation relay last opened (for reaction-time measurements).
  std::optional<Clock::time_point> last_excitation_off() const;

  // A fault becomes active `delay` after the next excitation-enable edge (or now, when
  // `on_excitation` is false), once: later excitation edges do not trigger it again. It stays
  // for `duration` (then the fixture is healthy again, as when a cable is plugged back in), or
  // until ClearFaults() when no duration is given.
  void InjectFault(SimFault fault, std::chrono::milliseconds delay, bool on_excitation = true,
                   std::optional<std::chrono::milliseconds> duration = std::nullopt);
  void ClearFaults();
  bool FaultActive(SimFault fault) const;
  // When the injected fault became visible (for reaction-time measurements).
  std::optional<Clock::time_point> fault_visible_at() const;

 private:
  bool FaultActiveLocked(SimFault fault, Clock::time_point now) const;
  // True when the fault was active at any time in [since, now].
  bool FaultSeenLocked(SimFault fault, Clock::time_point since, Clock::time_point now) const;
  void CheckAnsweringLocked(Clock::time_point now) const;
  FixtureInputs InputsLocked(Clock::time_point now) const;
  // The alive rule, evaluated lazily: opens a relay whose alive change is too old.
  void ExpireAliveLocked(Clock::time_point now) const;
  bool AliveFreshLocked(Clock::time_point now) const;

  SimBenchSettings settings_;
  const SimClock now_;
  mutable std::mutex mu_;
  std::optional<analysis::SimUnit> part_;
  double part_pressure_bar_ = 0.0;  // the clamp pressure the part in the fixture gets
  std::uint64_t parts_loaded_ = 0;
  bool clamp_cmd_ = false;
  std::optional<Clock::time_point> clamp_cmd_at_;  // none: never commanded, long released
  mutable bool excitation_ = false;
  bool lamp_pass_ = false, lamp_fail_ = false;
  PhasePair pair_ = PhasePair::kUV;
  mutable std::optional<Clock::time_point> excitation_off_at_;
  const Clock::time_point born_;
  std::optional<std::uint16_t> alive_;
  std::optional<Clock::time_point> alive_changed_at_;
  // Per SimLatch: the previous ReadInputs (or ClearLatch) of that input.
  std::array<Clock::time_point, kSimLatchCount> latch_since_;

  struct PendingFault {
    SimFault fault;
    std::chrono::milliseconds delay;
    bool on_excitation;
    Clock::time_point armed_at;
    std::optional<std::chrono::milliseconds> duration;
    std::optional<Clock::time_point> triggered_at;  // the excitation edge (on_excitation)
  };
  std::optional<Clock::time_point> FaultVisibleAtLocked() const;
  std::optional<PendingFault> fault_;
  mutable std::uint32_t frozen_heartbeat_ = 0;
};

}  // namespace eol::drivers
