#include "station/daemon/safety.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <random>
#include <thread>
#include <vector>

#include "analysis/text.h"
#include "station/daemon/reason_cause.h"

namespace eol::station {

using analysis::Fixed;
using analysis::ReasonCode;
using drivers::FixtureOutput;
using Clock = std::chrono::steady_clock;

namespace {

double Ms(Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); }

}  // namespace

bool HeartbeatMonitor::Update(std::uint32_t beat, Clock::time_point now) {
  if (!last_ || *last_ != beat) {
    last_ = beat;
    changed_at_ = now;
    return true;
  }
  return now - changed_at_ <= timeout_;
}

double HeartbeatMonitor::stale_ms(Clock::time_point now) const { return Ms(now - changed_at_); }

InterlockFinding FindInterlockFault(const drivers::FixtureInputs& in, const Recipe& r,
                                    bool require_clamp) {
  if (!in.estop_ok) return {cause::kEstopOpen, "emergency stop chain open"};
  if (!in.door_closed) return {cause::kDoorOpen, "door open"};
  if (!in.part_present) return {cause::kNoPart, "no part present"};
  if (require_clamp) {
    if (!in.clamped) return {cause::kClampNotConfirmed, "clamp not confirmed (clamped sensor off)"};
    // Written as "not inside" so that a pressure that is not a number is a fault too.
    if (!(in.clamp_pressure_bar >= r.clamp_pressure_lo_bar &&
          in.clamp_pressure_bar <= r.clamp_pressure_hi_bar))
      return {cause::kClampPressure, "clamp pressure " + Fixed(in.clamp_pressure_bar, 2) +
                                         " bar outside " + Fixed(r.clamp_pressure_lo_bar, 2) +
                                         ".." + Fixed(r.clamp_pressure_hi_bar, 2) + " bar"};
  }
  return {};
}

std::string InterlockFault(const drivers::FixtureInputs& in, const Recipe& r, bool require_clamp) {
  return FindInterlockFault(in, r, require_clamp).text;
}

double ReactionLimitMs(const SafetyOptions& s) {
  if (s.watchdog_reaction_ms > 0.0) return s.watchdog_reaction_ms;
  return std::max(100.0, 4.0 * s.watchdog_period_ms);
}

AliveSignal::AliveSignal(drivers::Fixture& fixture)
    : fixture_(fixture), value_(static_cast<std::uint16_t>(std::random_device{}())) {}

drivers::Status AliveSignal::Fresh() {
  drivers::Status s = Beat();
  return s.ok() ? Beat() : s;
}

drivers::Status AliveSignal::Beat() {
  return fixture_.WriteAlive(static_cast<std::uint16_t>(value_.fetch_add(1) + 1));
}

AlivePump::AlivePump(AliveSignal& alive, double period_ms)
    : alive_(alive), period_ms_(period_ms), thread_([this] {
        std::unique_lock<std::mutex> lock(mu_);
        while (!stop_) {
          if (const drivers::Status s = alive_.Beat(); !s.ok())
            spdlog::warn("station alive: {}", s.message());
          wake_.wait_for(lock, std::chrono::duration<double, std::milli>(period_ms_),
                         [this] { return stop_; });
        }
      }) {}

AlivePump::~AlivePump() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

ExcitationWatchdog::ExcitationWatchdog(WatchdogContext context)
    : c_(context),
      limit_ms_(ReactionLimitMs(c_.safety)),
      alive_period_(c_.safety.alive_period_ms),
      last_ok_(c_.clock.now()),
      last_alive_(last_ok_),
      thread_([this] { Run(); }) {}

ExcitationWatchdog::~ExcitationWatchdog() { Stop(c_.clock.now()); }

void ExcitationWatchdog::Stop(Clock::time_point excitation_off) {
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (stop_ && !thread_.joinable()) return;
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  std::lock_guard<std::mutex> lock(mu_);
  // The last stretch, from the last good read to the relay opening: a stall inside the
  // final period (the whole process frozen, then the sequencer first on resume) counts.
  const double gap = Ms(excitation_off - last_ok_);
  max_gap_ms_ = std::max(max_gap_ms_, gap);
  if (!fault_ && gap > limit_ms_) {
    fault_ = "watchdog stalled " + Fixed(gap, 0) + " ms (limit " + Fixed(limit_ms_, 0) +
             " ms) before excitation ended";
    c_.trips.fetch_add(1);
    spdlog::error("watchdog: {}", *fault_);
  }
}

std::optional<std::string> ExcitationWatchdog::fault() const {
  std::lock_guard<std::mutex> lock(mu_);
  return fault_;
}

std::optional<std::pair<double, double>> ExcitationWatchdog::pressure_range() const {
  std::lock_guard<std::mutex> lock(mu_);
  return pressure_;
}

double ExcitationWatchdog::max_gap_ms() const {
  std::lock_guard<std::mutex> lock(mu_);
  return max_gap_ms_;
}

void ExcitationWatchdog::Run() {
  const auto period = std::chrono::duration<double, std::milli>(c_.safety.watchdog_period_ms);
  for (;;) {
    const std::string why = Check();
    if (!why.empty()) return Trip(why);
    std::unique_lock<std::mutex> lock(mu_);
    if (wake_.wait_for(lock, period, [this] { return stop_; })) return;
  }
}

std::string ExcitationWatchdog::GapFault(Clock::time_point now, double read_ms) {
  std::lock_guard<std::mutex> lock(mu_);
  const double gap = Ms(now - last_ok_);
  max_gap_ms_ = std::max(max_gap_ms_, gap);
  if (gap <= limit_ms_) return "";
  return "watchdog stalled " + Fixed(gap, 0) + " ms (limit " + Fixed(limit_ms_, 0) + " ms" +
         (read_ms > 0.0 ? "; the fixture read took " + Fixed(read_ms, 0) + " ms" : "") + ")";
}

std::string ExcitationWatchdog::Check() {
  // A stall is seen before anything read after it is believed.
  if (std::string stall = GapFault(c_.clock.now(), 0.0); !stall.empty()) return stall;
  const auto t0 = c_.clock.now();
  auto in = c_.fixture.ReadInputs();
  const auto now = c_.clock.now();
  if (!in.ok())
    return "interlock lost during excitation: fixture not answering during excitation: " +
           in.status().message();
  if (std::string late = GapFault(now, Ms(now - t0)); !late.empty()) return late;
  {
    std::lock_guard<std::mutex> lock(mu_);
    last_ok_ = now;
    const double p = in.value().clamp_pressure_bar;
    pressure_ = pressure_
                    ? std::make_pair(std::min(pressure_->first, p), std::max(pressure_->second, p))
                    : std::make_pair(p, p);
  }
  if (std::string why = InterlockFault(in.value(), c_.recipe, true); !why.empty())
    return "interlock lost during excitation: " + why;
  if (!c_.heartbeat.Update(in.value().heartbeat, now))
    return "interlock lost during excitation: fixture heartbeat frozen for " +
           Fixed(c_.heartbeat.stale_ms(now), 0) + " ms";
  if (now - last_alive_ >= alive_period_) {
    last_alive_ = now;
    if (const drivers::Status s = c_.alive.Beat(); !s.ok())
      return "interlock lost during excitation: station_alive not written: " + s.message();
  }
  return "";
}

void ExcitationWatchdog::Trip(const std::string& why) {
  const drivers::Status off = c_.fixture.Write(FixtureOutput::kExcitationEnable, false);
  {
    // The cause is stored before the abort wakes the sequencer, which reads it.
    std::lock_guard<std::mutex> lock(mu_);
    fault_ = why;
  }
  c_.abort.store(true);
  c_.trips.fetch_add(1);
  spdlog::error("watchdog: {}; excitation off{}", why,
                off.ok() ? "" : " command failed (" + off.message() + ")");
}

// See safety.h. The steps and their order are the safety contract: excitation off first,
// whatever state the fixture is in; the clamp opened only when nobody can be hurt by it.
std::vector<analysis::Reason> DriveToSafeState(drivers::Fixture& fixture,
                                               const SafetyOptions& safety, bool clamp_commanded,
                                               const StationClock& clock) {
  std::vector<analysis::Reason> reasons;
  const auto give_up = clock.now() + std::chrono::duration_cast<Clock::duration>(
                                         std::chrono::duration<double>(safety.safe_state_retry_s));
  const auto pause =
      std::chrono::duration<double, std::milli>(std::max(safety.poll_period_ms, 50.0));
  // 1. Excitation off, always first, whatever state the fixture is in.
  int attempts = 0;
  drivers::Status off = drivers::Status::Ok();
  for (;;) {
    ++attempts;
    off = fixture.lifecycle() == drivers::Lifecycle::kError
              ? fixture.Connect()  // a fresh connection drives excitation off first
              : fixture.Write(FixtureOutput::kExcitationEnable, false);
    if (off.ok() || clock.now() >= give_up) break;
    clock.Sleep(pause);
  }
  if (!off.ok())
    reasons.push_back({ReasonCode::kFixture,
                       "excitation off not confirmed after " + std::to_string(attempts) +
                           " attempts: " + off.message() +
                           " (the relay is wired to drop on controller loss)",
                       std::string(cause::kExcitationOffUnconfirmed)});
  // 2. Unclamp only when it is safe: the controller answers, nobody is at the door, the
  //    emergency-stop chain is healthy. Otherwise leave the part clamped and say so.
  std::string unsafe;
  ReasonCode code = ReasonCode::kInterlock;
  for (;;) {
    if (fixture.lifecycle() == drivers::Lifecycle::kError) (void)fixture.Connect();
    auto in = fixture.ReadInputs();
    if (!in.ok()) {
      unsafe = "fixture not answering (" + in.status().message() + ")";
      code = ReasonCode::kFixture;
      if (clock.now() < give_up) {
        clock.Sleep(pause);
        continue;
      }
    } else if (!in.value().estop_ok) {
      unsafe = "emergency stop open";
    } else if (!in.value().door_closed) {
      unsafe = "door open";
    } else {
      unsafe.clear();
      (void)fixture.Activate();
      const drivers::Status s = fixture.Write(FixtureOutput::kClampCmd, false);
      if (!s.ok() && clock.now() < give_up) {
        clock.Sleep(pause);
        continue;
      }
      if (!s.ok())
        reasons.push_back({ReasonCode::kFixture, "unclamp not confirmed: " + s.message(),
                           std::string(cause::kClampLeftClosed)});
    }
    break;
  }
  if (!unsafe.empty())
    reasons.push_back({code, "clamp left as it is: " + unsafe,
                       clamp_commanded ? std::string(cause::kClampLeftClosed) : ""});
  (void)fixture.Deactivate();
  return reasons;
}

}  // namespace eol::station
