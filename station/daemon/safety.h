// The station's safety in one short unit, for a safety review to read alone: the
// interlocks, the controller's heartbeat, the station-alive signal, the excitation watchdog
// and the safe state after a fault. The sequencer (station/daemon/sequencer.h) decides when to
// excite; this unit decides when excitation must stop, and the fixture controller
// (drivers/fixture/modbus_map.h, can_map.h: "what the fixture builder must program") stops it by
// itself when the station cannot.
//
// During excitation, every watchdog_period_ms, the watchdog
//   1. checks its own loop: a gap between two successful interlock reads longer than the
//      reaction limit (ReactionLimitMs) is a fault, "watchdog stalled N ms (limit L ms)";
//      a stall of the whole process (SIGSTOP, swapping) is seen first thing on resume,
//      before any input read after it is believed, and also at the end of excitation
//      (Stop), so a stall inside the last period is never missed;
//   2. reads the interlocks (one request per table, never retried in excitation: a failed,
//      late, malformed or foreign-unit reply is an interlock loss) and the heartbeat; the
//      controller latches drops between reads, so a door that opened and closed inside a
//      stall is still seen;
//   3. writes a new station_alive value every alive_period_ms, without which the
//      controller opens the relay within its alive_timeout_ms (250 ms).
// On the first fault it opens the relay itself, stores the cause and raises the abort flag
// the acquisition watches. The longest gap of the excitation is kept for the record
// (conditions.watchdog_max_gap_ms), so every stall leaves a trace.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include "analysis/qc/measurement.h"
#include "drivers/fixture/fixture.h"
#include "station/daemon/config.h"
#include "station/daemon/recipe.h"
#include "station/daemon/station_clock.h"

namespace eol::station {

// Tracks the fixture controller's heartbeat counter: alive while it keeps changing.
class HeartbeatMonitor {
 public:
  explicit HeartbeatMonitor(std::chrono::milliseconds timeout) : timeout_(timeout) {}
  // Returns false once the counter has not changed for longer than the timeout.
  bool Update(std::uint32_t beat, std::chrono::steady_clock::time_point now);
  double stale_ms(std::chrono::steady_clock::time_point now) const;

 private:
  std::chrono::milliseconds timeout_;
  std::optional<std::uint32_t> last_;
  std::chrono::steady_clock::time_point changed_at_{};
};

// Empty when every interlock for exciting the stator holds; otherwise the first one broken,
// named with its value ("door open", "clamp pressure 3.10 bar outside 4.50..6.50 bar").
std::string InterlockFault(const drivers::FixtureInputs& in, const Recipe& recipe,
                           bool require_clamp);

// The same check with the broken interlock's cause key (station/daemon/reason_cause.h); both empty
// when every interlock holds.
struct InterlockFinding {
  std::string_view cause;
  std::string text;
};
InterlockFinding FindInterlockFault(const drivers::FixtureInputs& in, const Recipe& recipe,
                                    bool require_clamp);

// The safe state, after any fault of a test: excitation off first, whatever state the
// fixture is in (a controller in error is reconnected: a fresh connection drives excitation
// off first); then the clamp opened only when that is safe: the controller answers, the
// emergency-stop chain is healthy and the door is closed; otherwise the part stays clamped.
// On a communication loss both steps are retried every max(poll_period_ms, 50) ms until
// confirmed or safe_state_retry_s has passed. Returns what could not be confirmed, as reasons
// for the record ("excitation off not confirmed after N attempts: ...", "clamp left as it is:
// door open", ...); `clamp_commanded` (the clamp was commanded closed in this test) marks the
// latter with the cause clamp_left_closed. Ends with the fixture deactivated. Its deadline
// and pauses are on `clock` (station/daemon/station_clock.h).
std::vector<analysis::Reason> DriveToSafeState(drivers::Fixture& fixture,
                                               const SafetyOptions& safety, bool clamp_commanded,
                                               const StationClock& clock);

// The longest gap between two successful interlock reads the watchdog accepts during
// excitation: safety.watchdog_reaction_ms, or when that is 0, 4 x watchdog_period_ms and
// at least 100 ms.
double ReactionLimitMs(const SafetyOptions& safety);

// The station-alive counter (the fixture's station_alive signal). Thread-safe: each Beat
// writes the next value (wrapping at 2^16), so consecutive writes always differ.
class AliveSignal {
 public:
  explicit AliveSignal(drivers::Fixture& fixture);
  drivers::Status Beat();
  // Two beats: whatever value the controller holds (left by an earlier instance, a
  // restarted daemon, another counter), at least one of two consecutive values differs
  // from it, so the controller sees a change. Before closing the relay.
  drivers::Status Fresh();

 private:
  drivers::Fixture& fixture_;
  std::atomic<std::uint16_t> value_;  // starts at random: another instance's last value is unlikely
};

// Writes station_alive every alive_period_ms on a thread of its own while it lives: for
// excitation outside the sequencer (eol calibrate). Write failures are logged; the
// controller then opens the relay by itself.
class AlivePump {
 public:
  AlivePump(AliveSignal& alive, double period_ms);
  ~AlivePump();
  AlivePump(const AlivePump&) = delete;
  AlivePump& operator=(const AlivePump&) = delete;

 private:
  AliveSignal& alive_;
  const double period_ms_;
  std::mutex mu_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::thread thread_;  // last: starts after the members it uses exist
};

// What the watchdog needs; every reference outlives it.
struct WatchdogContext {
  drivers::Fixture& fixture;
  const Recipe& recipe;
  HeartbeatMonitor& heartbeat;  // touched only by the watchdog while it runs
  AliveSignal& alive;
  SafetyOptions safety;
  std::atomic<bool>& abort;           // raised on a trip: the acquisition stops
  std::atomic<std::uint64_t>& trips;  // counted on a trip
  // Gaps and the alive period are measured on clock.now (station/daemon/station_clock.h); the
  // period between two reads is paced in real time.
  StationClock clock = {};
};

// Polls the interlocks while the stator is excited (see the top of this file). Starts in
// its constructor; the caller writes station_alive and closes the relay after that.
class ExcitationWatchdog {
 public:
  using Clock = std::chrono::steady_clock;
  explicit ExcitationWatchdog(WatchdogContext context);
  ~ExcitationWatchdog();  // Stop(clock.now())
  ExcitationWatchdog(const ExcitationWatchdog&) = delete;
  ExcitationWatchdog& operator=(const ExcitationWatchdog&) = delete;

  // Stops the thread now, not after the rest of its period; idempotent. `excitation_off`
  // is when the relay was commanded off: a gap from the last good read to it longer than
  // the limit is a stall too. fault(), pressure_range() and max_gap_ms() are final once it
  // returns.
  void Stop(Clock::time_point excitation_off);
  // The cause of a trip: "interlock lost during excitation: door open", "watchdog stalled
  // 1500 ms (limit 100 ms)", ...
  std::optional<std::string> fault() const;
  // Clamp pressure seen during excitation (bar): {min, max}; empty before the first read.
  std::optional<std::pair<double, double>> pressure_range() const;
  // The longest gap between two successful reads (or to the end of excitation), ms.
  double max_gap_ms() const;

 private:
  void Run();
  // One period: empty when all is well, else the fault's text.
  std::string Check();
  // A gap since the last good read beyond the limit, as a fault text ("" when none);
  // `read_ms` > 0 names how long the read inside it took.
  std::string GapFault(Clock::time_point now, double read_ms);
  void Trip(const std::string& why);

  WatchdogContext c_;
  const double limit_ms_;
  const std::chrono::duration<double, std::milli> alive_period_;
  mutable std::mutex mu_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::optional<std::string> fault_;
  std::optional<std::pair<double, double>> pressure_;
  Clock::time_point last_ok_;
  Clock::time_point last_alive_;
  double max_gap_ms_ = 0.0;
  std::thread thread_;  // last: starts after the members it uses exist
};

}  // namespace eol::station
