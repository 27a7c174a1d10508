// What the station publishes: its live state and finished verdicts. The sequencer writes
// here only after the record is stored; the HTTP API, the event stream and the operator page
// read from here. Thread-safe.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "db/test_record.h"
#include "station/daemon/health.h"

namespace eol::station {

// The board's state is the sequencer's (station/daemon/sequencer.h, named by its ToString: the page
// and /metrics read those strings), or "idle" before the first test.
enum class SeqState;

// The board's counts of verdicts: of one day, station local time.
struct VerdictCounts {
  std::uint64_t pass = 0, fail = 0, error = 0, aborted = 0;
  void Add(analysis::Outcome outcome);
};

// "YYYY-MM-DD" of `t` in the station's local time, and that day's first instant.
std::string LocalDay(std::chrono::system_clock::time_point t);
std::chrono::system_clock::time_point LocalMidnight(std::chrono::system_clock::time_point t);

class StatusBoard {
 public:
  explicit StatusBoard(std::string station_id, std::string recipe_id = "",
                       std::string recipe_hash = "");

  // A sequencer state was entered.
  void OnState(const std::string& serial, SeqState state, const std::string& detail);
  // A finished, stored record. The counts start again on a new local day.
  void OnVerdict(const db::TestRecord& record);
  // Shift continuity, at start before any verdict: the newest stored tests
  // (newest first; the last 20 are kept, as OnVerdict keeps them) and the counts of `day`
  // (LocalDay) so far, as the store holds them. The lamp ("last") stays empty: no unit was
  // tested since the start.
  void Restore(const std::vector<db::TestRecord>& newest_first, VerdictCounts counts,
               std::string day);
  // The recipe changed (between tests).
  void SetRecipe(const std::string& recipe_id, const std::string& recipe_hash);
  // Free text for the operator ("store write failed: ..."). The next verdict clears it:
  // a message is about the station's last moments, not about the unit tested after.
  void SetMessage(const std::string& message);
  // Simulators or recorded data instead of the fixture and the DAQ: the page shows
  // SIMULATION and every record says so (conditions.simulation). Set once at start.
  void SetSimulation(const std::string& why);
  // Readiness (station/daemon/health.h): ready while no cause is raised. SetCause raises one (or
  // updates its detail, the technical text); ClearCause lowers it. Each change is a
  // "readiness" event.
  void SetCause(NotReadyCause cause, const std::string& detail);
  void ClearCause(NotReadyCause cause);
  bool HasCause(NotReadyCause cause) const;
  // The self-check lockout (station/daemon/self_check.h LockoutState::ToJson): {"locked", "reason",
  // "good", "limit", "tests_since_check"}; null while self-checks are off.
  void SetLockout(const nlohmann::json& lockout);

  // {"station_id", "state", "serial", "detail", "message",
  //  "ready", "not_ready_reason" (every raised cause's detail, "; "-joined, "" when ready),
  //  "not_ready_code" (the first raised cause's code, "" when ready), "not_ready_text" (its
  //  operator text), "not_ready": [{code, reason, operator_text}] (every raised cause, by
  //  priority), "simulation": "" | "<why>", "recipe": {...},
  //  "counts": {"pass", "fail", "error", "aborted", "day"} (the local day's verdicts, stored
  //  ones rebuilt from the store at start),
  //  "last": {serial, outcome, reasons [{code, text}], measurements, finished_at, id,
  //           kind: "production" | "self_check", attempt, max_tests (db/test_record.h: the
  //           retest "attempt of max_tests")} | null,
  //  "recent": [...], "lockout": {...} | null}
  nlohmann::json Snapshot() const;

  // Events (state changes and verdicts) with increasing sequence numbers. Blocks up to
  // `wait` for an event newer than `after`; returns those still held (the last 256).
  std::vector<std::pair<std::uint64_t, nlohmann::json>> EventsAfter(
      std::uint64_t after, std::chrono::milliseconds wait) const;
  std::uint64_t last_event() const;

 private:
  void PushEventLocked(nlohmann::json event);
  nlohmann::json ReadinessLocked() const;

  const std::string station_id_;
  std::string recipe_id_;
  std::string recipe_hash_;
  mutable std::mutex mu_;
  mutable std::condition_variable cv_;
  std::optional<SeqState> state_;  // nullopt: idle
  std::string serial_;
  std::string detail_;
  std::string message_;
  std::string simulation_;  // empty: real fixture and DAQ
  // The raised causes and their details, by priority; ready when empty.
  std::map<NotReadyCause, std::string> causes_ = {
      {NotReadyCause::kDriversNotConnected, "drivers not connected yet"}};
  nlohmann::json last_;     // null until the first verdict
  nlohmann::json lockout_;  // null while self-checks are off
  std::deque<nlohmann::json> recent_;
  VerdictCounts counts_;
  std::string day_;  // LocalDay of the counts; "" until the first verdict or Restore
  std::deque<std::pair<std::uint64_t, nlohmann::json>> events_;
  std::uint64_t next_event_ = 1;
};

// The summary of a record that the display and the status show (no curves).
nlohmann::json RecordSummary(const db::TestRecord& record);

}  // namespace eol::station
