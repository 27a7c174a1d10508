#include "station/daemon/status_board.h"

#include <ctime>

#include "station/daemon/sequencer.h"  // ToString(SeqState)

namespace eol::station {

nlohmann::json RecordSummary(const db::TestRecord& r) {
  return {
      {"id", r.id},
      {"serial", r.serial},
      {"outcome", analysis::ToString(r.outcome)},
      {"reasons", r.reasons},
      {"measurements", r.measurements},
      {"started_at", r.started_at},
      {"finished_at", r.finished_at},
      {"kind", r.kind},  // a master part's self-check is no production unit
      // "retest 2 of 3": which test of its serial (1: the first; 0: not stored) of how many
      // the recipe allows (0: no limit).
      {"attempt", r.attempt},
      {"max_tests", r.max_tests},
      // With variants (station/daemon/variants.h) the recipe picked for this unit and its variant.
      {"recipe",
       {{"id", r.recipe_id},
        {"version", r.recipe_version},
        {"hash", r.recipe_hash},
        {"variant",
         r.conditions.variant ? nlohmann::json(*r.conditions.variant) : nlohmann::json()}}}};
}

void VerdictCounts::Add(analysis::Outcome outcome) {
  switch (outcome) {
    case analysis::Outcome::kPass:
      ++pass;
      break;
    case analysis::Outcome::kFail:
      ++fail;
      break;
    case analysis::Outcome::kError:
      ++error;
      break;
    case analysis::Outcome::kAborted:
      ++aborted;
      break;
  }
}

std::string LocalDay(std::chrono::system_clock::time_point t) {
  const std::time_t tt = std::chrono::system_clock::to_time_t(t);
  std::tm local{};
  localtime_r(&tt, &local);
  char day[16];
  std::strftime(day, sizeof day, "%Y-%m-%d", &local);
  return day;
}

std::chrono::system_clock::time_point LocalMidnight(std::chrono::system_clock::time_point t) {
  const std::time_t tt = std::chrono::system_clock::to_time_t(t);
  std::tm local{};
  localtime_r(&tt, &local);
  local.tm_hour = local.tm_min = local.tm_sec = 0;
  local.tm_isdst = -1;  // whatever holds at midnight
  return std::chrono::system_clock::from_time_t(std::mktime(&local));
}

StatusBoard::StatusBoard(std::string station_id, std::string recipe_id, std::string recipe_hash)
    : station_id_(std::move(station_id)),
      recipe_id_(std::move(recipe_id)),
      recipe_hash_(std::move(recipe_hash)) {}

void StatusBoard::PushEventLocked(nlohmann::json event) {
  events_.emplace_back(next_event_++, std::move(event));
  while (events_.size() > 256) events_.pop_front();
  cv_.notify_all();
}

void StatusBoard::OnState(const std::string& serial, SeqState state, const std::string& detail) {
  std::lock_guard<std::mutex> lock(mu_);
  state_ = state;
  serial_ = serial;
  detail_ = detail;
  PushEventLocked(
      {{"type", "state"}, {"state", ToString(state)}, {"serial", serial}, {"detail", detail}});
}

void StatusBoard::OnVerdict(const db::TestRecord& record) {
  std::lock_guard<std::mutex> lock(mu_);
  last_ = RecordSummary(record);
  recent_.push_front(last_);
  while (recent_.size() > 20) recent_.pop_back();
  const std::string today = LocalDay(std::chrono::system_clock::now());
  if (today != day_) counts_ = VerdictCounts{};
  day_ = today;
  counts_.Add(record.outcome);
  PushEventLocked({{"type", "verdict"}, {"record", last_}});
  if (!message_.empty()) {
    message_.clear();
    PushEventLocked({{"type", "message"}, {"message", ""}});
  }
}

void StatusBoard::Restore(const std::vector<db::TestRecord>& newest_first, VerdictCounts counts,
                          std::string day) {
  std::lock_guard<std::mutex> lock(mu_);
  recent_.clear();
  for (const db::TestRecord& r : newest_first) {
    if (recent_.size() == 20) break;
    recent_.push_back(RecordSummary(r));
  }
  counts_ = counts;
  day_ = std::move(day);
}

void StatusBoard::SetRecipe(const std::string& recipe_id, const std::string& recipe_hash) {
  std::lock_guard<std::mutex> lock(mu_);
  recipe_id_ = recipe_id;
  recipe_hash_ = recipe_hash;
  PushEventLocked({{"type", "recipe"}, {"id", recipe_id}, {"hash", recipe_hash}});
}

void StatusBoard::SetMessage(const std::string& message) {
  std::lock_guard<std::mutex> lock(mu_);
  if (message == message_) return;
  message_ = message;
  PushEventLocked({{"type", "message"}, {"message", message}});
}

void StatusBoard::SetSimulation(const std::string& why) {
  std::lock_guard<std::mutex> lock(mu_);
  simulation_ = why;
}

void StatusBoard::SetCause(NotReadyCause cause, const std::string& detail) {
  std::lock_guard<std::mutex> lock(mu_);
  const auto it = causes_.find(cause);
  if (it != causes_.end() && it->second == detail) return;
  causes_[cause] = detail;
  nlohmann::json event = ReadinessLocked();
  event["type"] = "readiness";
  PushEventLocked(std::move(event));
}

void StatusBoard::ClearCause(NotReadyCause cause) {
  std::lock_guard<std::mutex> lock(mu_);
  if (causes_.erase(cause) == 0) return;
  nlohmann::json event = ReadinessLocked();
  event["type"] = "readiness";
  PushEventLocked(std::move(event));
}

bool StatusBoard::HasCause(NotReadyCause cause) const {
  std::lock_guard<std::mutex> lock(mu_);
  return causes_.count(cause) > 0;
}

nlohmann::json StatusBoard::ReadinessLocked() const {
  std::string reason;
  nlohmann::json all = nlohmann::json::array();
  for (const auto& [cause, detail] : causes_) {
    reason += (reason.empty() ? "" : "; ") + detail;
    all.push_back(
        {{"code", Code(cause)}, {"reason", detail}, {"operator_text", OperatorText(cause)}});
  }
  const bool ready = causes_.empty();
  return {{"ready", ready},
          {"not_ready_reason", reason},
          {"not_ready_code", ready ? "" : Code(causes_.begin()->first)},
          {"not_ready_text", ready ? "" : OperatorText(causes_.begin()->first)},
          {"not_ready", all}};
}

void StatusBoard::SetLockout(const nlohmann::json& lockout) {
  std::lock_guard<std::mutex> lock(mu_);
  if (lockout == lockout_) return;
  lockout_ = lockout;
  PushEventLocked({{"type", "lockout"}, {"lockout", lockout}});
}

nlohmann::json StatusBoard::Snapshot() const {
  std::lock_guard<std::mutex> lock(mu_);
  nlohmann::json s = ReadinessLocked();
  s.update({{"station_id", station_id_},
            {"state", state_ ? ToString(*state_) : "idle"},
            {"serial", serial_},
            {"detail", detail_},
            {"message", message_},
            {"simulation", simulation_},
            {"recipe", {{"id", recipe_id_}, {"hash", recipe_hash_}}},
            {"counts",
             {{"pass", counts_.pass},
              {"fail", counts_.fail},
              {"error", counts_.error},
              {"aborted", counts_.aborted},
              {"day", day_}}},
            {"last", last_},
            {"recent", recent_},
            {"lockout", lockout_}});
  return s;
}

std::vector<std::pair<std::uint64_t, nlohmann::json>> StatusBoard::EventsAfter(
    std::uint64_t after, std::chrono::milliseconds wait) const {
  std::unique_lock<std::mutex> lock(mu_);
  cv_.wait_for(lock, wait, [&] { return next_event_ - 1 > after; });
  std::vector<std::pair<std::uint64_t, nlohmann::json>> out;
  for (const auto& e : events_)
    if (e.first > after) out.push_back(e);
  return out;
}

std::uint64_t StatusBoard::last_event() const {
  std::lock_guard<std::mutex> lock(mu_);
  return next_event_ - 1;
}

}  // namespace eol::station
