// The time the simulated bench lives by. The bench asks a SimClock for "now" whenever its
// physics depends on time (clamp travel, pressure ramp, heartbeat, when a fault shows and
// how long it lasts). The station, `eol fixture-sim` and the emulators run on the steady
// clock (the default); tests hand the bench a ManualClock and advance it, so that a test
// of clamp timing or of a fault after N ms states the time instead of sleeping through it.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <stdexcept>

namespace eol::drivers {

// "now" on the steady clock's time line: the bench only ever takes differences of these.
using SimClock = std::function<std::chrono::steady_clock::time_point()>;

inline SimClock SteadySimClock() {
  return [] { return std::chrono::steady_clock::now(); };
}

// A clock that stands still until told to move. Thread-safe: the emulators read the bench
// (and so the clock) on their own threads while the test advances it. It starts an hour
// after the steady clock's epoch, so that no time point a bench computes from it lies
// before the epoch.
class ManualClock {
 public:
  using time_point = std::chrono::steady_clock::time_point;

  time_point now() const {
    std::lock_guard<std::mutex> lock(mu_);
    return now_;
  }
  // Moves time forward; a negative step is a programmer error (a steady clock never goes
  // back) and is refused by std::logic_error.
  void Advance(std::chrono::steady_clock::duration step);
  template <typename Rep, typename Period>
  void Advance(std::chrono::duration<Rep, Period> step) {
    Advance(std::chrono::duration_cast<std::chrono::steady_clock::duration>(step));
  }
  // Seconds, as the bench's settings state times (e.g. clamp_close_s).
  void AdvanceSeconds(double s) { Advance(std::chrono::duration<double>(s)); }

  // A SimClock reading this clock; it shares ownership, so the clock outlives the bench.
  static SimClock Of(const std::shared_ptr<ManualClock>& clock) {
    return [clock] { return clock->now(); };
  }

 private:
  mutable std::mutex mu_;
  time_point now_ = time_point{} + std::chrono::hours(1);
};

inline void ManualClock::Advance(std::chrono::steady_clock::duration step) {
  if (step < std::chrono::steady_clock::duration::zero())
    throw std::logic_error("ManualClock::Advance: a steady clock never goes back");
  std::lock_guard<std::mutex> lock(mu_);
  now_ += step;
}

}  // namespace eol::drivers
