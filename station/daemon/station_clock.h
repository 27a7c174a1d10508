// The time the station lives by, passed in. The sequencer (SequencerOptions::clock), its
// excitation watchdog (WatchdogContext::clock) and the station (Station's constructor, which
// hands its clock to the sequencer and to the idle look) read every time they decide by from
// a StationClock, never from std::chrono directly:
//   now    the steady time line: deadlines (clamp, release, safe-state retries, a stuck
//          test), the watchdog's gaps, the heartbeat's staleness, the trace's milliseconds;
//   wall   the calendar: a record's started_at / finished_at and the self-check lockout's
//          "older than every_hours";
//   sleep  the pause between two polls of the sequencer (clamp, release, safe state).
// A default-constructed StationClock is the real one (steady_clock, system_clock,
// std::this_thread::sleep_for): production code passes nothing and runs as before.
// Background loops (the watchdog's period, the alive pump, the idle look, the health loop)
// are paced in real time by condition waits; only what they measure comes from `now`.
// Tests pass a clock made from a drivers::ManualClock (tests/support/manual_station_clock.h):
// `sleep` advances that clock, so a poll that waits 0.3 s for a release takes no real time,
// and the simulated bench on the same ManualClock moves with it.
#pragma once

#include <chrono>
#include <functional>
#include <thread>

namespace eol::station {

struct StationClock {
  using Steady = std::chrono::steady_clock;
  using Wall = std::chrono::system_clock;

  // The same type as the simulated bench's drivers::SimClock (drivers/sim/sim_clock.h, a
  // folder the station may not include), so one ManualClock::Of(clock) serves both.
  std::function<Steady::time_point()> now = [] { return Steady::now(); };
  std::function<Wall::time_point()> wall = [] { return Wall::now(); };
  std::function<void(Steady::duration)> sleep = [](Steady::duration d) {
    std::this_thread::sleep_for(d);
  };

  // sleep(), for any duration type (the options state milliseconds as doubles).
  template <typename Rep, typename Period>
  void Sleep(std::chrono::duration<Rep, Period> d) const {
    sleep(std::chrono::duration_cast<Steady::duration>(d));
  }
};

}  // namespace eol::station
