#include "station/daemon/health.h"

#include <algorithm>

#include "analysis/text.h"

namespace eol::station {
namespace {

struct CauseText {
  const char* code;
  const char* operator_text;
};

CauseText Text(NotReadyCause cause) {
  switch (cause) {
    case NotReadyCause::kClampNotReleased:
      return {"clamp_not_released", "Clamp did not open - call maintenance to free the part"};
    case NotReadyCause::kEstopOpen:
      return {"estop_open", "Emergency stop pressed - release it when it is safe"};
    case NotReadyCause::kFixtureUnreachable:
      return {"fixture_unreachable", "Fixture controller not answering - call maintenance"};
    case NotReadyCause::kHeartbeatFrozen:
      return {"fixture_heartbeat_frozen", "Fixture controller stopped - call maintenance"};
    case NotReadyCause::kAcquisitionUnavailable:
      return {"acquisition_unavailable", "Measuring device not connected - call maintenance"};
    case NotReadyCause::kDriversNotConnected:
      return {"drivers_not_connected", "Station starting - wait"};
    case NotReadyCause::kRecipeInvalid:
      return {"recipe_invalid", "No valid test recipe - call the quality engineer"};
    case NotReadyCause::kStoreWriteFailed:
      return {"store_write_failed", "Results cannot be saved - call maintenance"};
    case NotReadyCause::kStoreLostVerdicts:
      return {"store_lost_verdicts",
              "Recent results were lost from the database - tell the quality engineer"};
  }
  return {"unknown", "Station not ready - call maintenance"};
}

}  // namespace

const char* Code(NotReadyCause cause) { return Text(cause).code; }

const char* OperatorText(NotReadyCause cause) { return Text(cause).operator_text; }

std::optional<NotReadyCause> ParseNotReadyCode(std::string_view code) {
  for (NotReadyCause c : kNotReadyCauses)
    if (code == Code(c)) return c;
  return std::nullopt;
}

FixtureProbe::FixtureProbe(drivers::Fixture& fixture, std::chrono::milliseconds heartbeat_timeout)
    : fixture_(fixture), heartbeat_timeout_(heartbeat_timeout), heartbeat_(heartbeat_timeout) {}

std::vector<FixtureProbe::Finding> FixtureProbe::Look(Clock::time_point now) {
  const drivers::Lifecycle state = fixture_.lifecycle();
  if (state != drivers::Lifecycle::kInactive && state != drivers::Lifecycle::kActive) {
    if (const drivers::Status s = fixture_.Connect(); !s.ok()) {
      heartbeat_ = HeartbeatMonitor(heartbeat_timeout_);  // a controller that returns starts anew
      return {{NotReadyCause::kFixtureUnreachable, "fixture unavailable: " + s.message()}};
    }
  }
  const drivers::StatusOr<drivers::FixtureInputs> in = fixture_.ReadInputs();
  if (!in.ok()) {
    heartbeat_ = HeartbeatMonitor(heartbeat_timeout_);
    return {{NotReadyCause::kFixtureUnreachable, "fixture unavailable: " + in.status().message()}};
  }
  std::vector<Finding> found;
  if (!heartbeat_.Update(in.value().heartbeat, now))
    found.emplace_back(NotReadyCause::kHeartbeatFrozen,
                       "fixture controller heartbeat frozen at " +
                           std::to_string(in.value().heartbeat) + " for " +
                           analysis::Fixed(heartbeat_.stale_ms(now), 0) + " ms (limit " +
                           std::to_string(heartbeat_timeout_.count()) + " ms)");
  if (!in.value().estop_ok)
    found.emplace_back(NotReadyCause::kEstopOpen, "emergency stop chain open");
  return found;
}

PeriodicTask::PeriodicTask(std::chrono::milliseconds period, std::function<void()> tick)
    : period_(period), tick_(std::move(tick)), thread_([this] {
        std::unique_lock<std::mutex> lock(mu_);
        auto next = std::chrono::steady_clock::now();
        while (!stop_) {
          lock.unlock();
          tick_();
          lock.lock();
          // At a fixed rate: a slow tick shortens the wait after it, never the rate.
          next = std::max(next + period_, std::chrono::steady_clock::now());
          wake_.wait_until(lock, next, [this] { return stop_; });
        }
      }) {}

PeriodicTask::~PeriodicTask() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

}  // namespace eol::station
