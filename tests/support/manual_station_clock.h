// Test support: station clocks (station/daemon/station_clock.h) that run on a drivers::ManualClock,
// so a test states the time that passes instead of sleeping through it.
//
//   ManualStationClock  everything on the manual clock. The sequencer's pause between two
//                       polls advances it: a poll that waits 0.3 s for a release takes no
//                       real time. The simulated bench must run on the same ManualClock
//                       (SimBench(settings, ManualClock::Of(clock))) and be driven in-process
//                       (SimFixture), so the bench moves exactly as the station waits.
//   ManualWallClock     only the calendar on the manual clock (record timestamps, the
//                       self-check lockout's age); steady time and pauses stay real, for a
//                       station whose bench runs in real time.
// The wall clock starts at the real time when the clock is made, so records are dated today.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <thread>

#include "drivers/sim/sim_clock.h"
#include "station/daemon/station_clock.h"

namespace eol::testing {

namespace internal {
inline std::function<std::chrono::system_clock::time_point()> WallOn(
    const std::shared_ptr<drivers::ManualClock>& clock) {
  const auto wall0 = std::chrono::system_clock::now();
  const auto steady0 = clock->now();
  return [clock, wall0, steady0] {
    return wall0 +
           std::chrono::duration_cast<std::chrono::system_clock::duration>(clock->now() - steady0);
  };
}
}  // namespace internal

inline station::StationClock ManualStationClock(
    const std::shared_ptr<drivers::ManualClock>& clock) {
  station::StationClock c;
  c.now = drivers::ManualClock::Of(clock);
  c.wall = internal::WallOn(clock);
  c.sleep = [clock](std::chrono::steady_clock::duration d) {
    clock->Advance(d);
    std::this_thread::yield();  // threads reading the bench see the new time
  };
  return c;
}

inline station::StationClock ManualWallClock(const std::shared_ptr<drivers::ManualClock>& clock) {
  station::StationClock c;
  c.wall = internal::WallOn(clock);
  return c;
}

}  // namespace eol::testing
