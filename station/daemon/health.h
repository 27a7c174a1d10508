// The station's live health: why it is not ready, as typed causes, and the idle
// look at the fixture controller that raises and clears the fixture's causes without a test.
//
// Every reason the station is not ready is one NotReadyCause with a stable code (the API's
// "not_ready_code", the page's data-code; never renamed), and a text for the operator. The
// technical detail (which address, which error) travels beside it. The status board
// (station/daemon/status_board.h) holds the causes raised now; the station is ready when none is.
//
// While no test runs or waits, the station looks at the fixture controller every
// health.period_ms (station/daemon/config.h; 500 ms by default) through the fixture driver's own
// interface (FixtureProbe): a link that is down is reconnected (Fixture::Connect, which like
// every connect drives excitation off and nothing else), the inputs are read once, and the
// controller's heartbeat counter is watched. Nothing is written otherwise: no clamp, no
// excitation, no station_alive. A lost controller is seen within one period plus one failed
// read (the driver's attempts x response_timeout_ms plus its back-offs: 150 ms on a refused
// connection, 750 ms on a silent one with the defaults); its return within one period.
//
// Adding a cause: a value in NotReadyCause (its place is its priority: the first raised is
// the one the page headlines), its code and operator text in health.cc (the test
// tests/station/live_health_test.cc fails when one is missing or a code is used twice), then
// SetCause where it is detected and ClearCause where it is known to be gone.
#pragma once

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include "drivers/fixture/fixture.h"
#include "station/daemon/safety.h"

namespace eol::station {

// In order of priority (the first raised is headlined).
enum class NotReadyCause {
  kClampNotReleased,        // a clamp that did not open behind a published verdict
  kEstopOpen,               // the emergency-stop chain is open (seen while idle)
  kFixtureUnreachable,      // the fixture controller does not answer (connect or read fails)
  kHeartbeatFrozen,         // the controller answers but its heartbeat counter stands still
  kAcquisitionUnavailable,  // the DAQ does not connect
  kDriversNotConnected,     // before the station has tried its drivers (start-up)
  kRecipeInvalid,           // the configured recipe does not load or is not approved
  kStoreWriteFailed,        // the last store write failed (a full disk)
  kStoreLostVerdicts,       // the store lost acknowledged verdicts (named until the next test)
};

inline constexpr NotReadyCause kNotReadyCauses[] = {
    NotReadyCause::kClampNotReleased,       NotReadyCause::kEstopOpen,
    NotReadyCause::kFixtureUnreachable,     NotReadyCause::kHeartbeatFrozen,
    NotReadyCause::kAcquisitionUnavailable, NotReadyCause::kDriversNotConnected,
    NotReadyCause::kRecipeInvalid,          NotReadyCause::kStoreWriteFailed,
    NotReadyCause::kStoreLostVerdicts};

// The fixture controller's causes: what FixtureProbe raises and clears.
inline constexpr NotReadyCause kFixtureCauses[] = {
    NotReadyCause::kEstopOpen, NotReadyCause::kFixtureUnreachable, NotReadyCause::kHeartbeatFrozen};

// "fixture_unreachable", ...: stable, snake_case.
const char* Code(NotReadyCause cause);
// What the operator does: "Fixture controller not answering - call maintenance".
const char* OperatorText(NotReadyCause cause);
std::optional<NotReadyCause> ParseNotReadyCode(std::string_view code);

// One idle look at the fixture controller. Not thread-safe; the caller makes sure no test
// uses the fixture meanwhile (the fixture's own lock only serialises single calls).
class FixtureProbe {
 public:
  using Clock = std::chrono::steady_clock;
  // A cause raised by a look, with its technical detail.
  using Finding = std::pair<NotReadyCause, std::string>;

  FixtureProbe(drivers::Fixture& fixture, std::chrono::milliseconds heartbeat_timeout);
  // Reconnects a link that is down, reads the inputs once and checks the heartbeat and the
  // emergency-stop chain at `now`. Returns the fixture causes that hold (none: healthy);
  // every other cause of kFixtureCauses is gone.
  std::vector<Finding> Look(Clock::time_point now);

 private:
  drivers::Fixture& fixture_;
  const std::chrono::milliseconds heartbeat_timeout_;
  HeartbeatMonitor heartbeat_;
};

// Calls `tick` every `period` on a thread of its own until destroyed (the first call at
// once; at a fixed rate: a tick longer than the period is followed by the next at once). The
// destructor waits for a tick in flight. Paced in real time (a condition wait on the steady
// clock); what a tick measures comes from the station's clock (station/daemon/station_clock.h).
class PeriodicTask {
 public:
  PeriodicTask(std::chrono::milliseconds period, std::function<void()> tick);
  ~PeriodicTask();
  PeriodicTask(const PeriodicTask&) = delete;
  PeriodicTask& operator=(const PeriodicTask&) = delete;

 private:
  const std::chrono::milliseconds period_;
  const std::function<void()> tick_;
  std::mutex mu_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::thread thread_;  // last: starts after the members it uses exist
};

}  // namespace eol::station
