#include "station/daemon/self_check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string_view>

#include "analysis/qc/measurement_names.h"
#include "analysis/text.h"
#include "db/clock.h"

namespace eol::station {
namespace {

using analysis::Fixed;

std::string LimitText(const analysis::Limit& l) {
  return (l.lo ? Fixed(*l.lo, 1) : std::string("-inf")) + ".." +
         (l.hi ? Fixed(*l.hi, 1) : std::string("+inf"));
}

const analysis::Measurement* FindMeasurement(const db::TestRecord& r, std::string_view name) {
  for (const auto& m : r.measurements)
    if (m.name == name) return &m;
  return nullptr;
}

nlohmann::json EntryJson(const std::optional<db::SelfCheckEntry>& e) {
  if (!e) return nullptr;
  return {{"test_id", e->test_id}, {"at", e->at},         {"serial", e->serial},
          {"master", e->master},   {"passed", e->passed}, {"detail", e->detail}};
}

}  // namespace

std::optional<std::string> MasterRole(const SelfCheckConfig& c, const std::string& serial) {
  if (!c.enabled()) return std::nullopt;
  if (serial == c.good_master) return "good";
  if (serial == c.limit_master) return "limit";
  return std::nullopt;
}

nlohmann::json JudgeMasterTest(const std::string& master, const db::TestRecord& r) {
  const std::string who = master + " master " + r.serial;
  const std::string outcome = analysis::ToString(r.outcome);
  const std::string first = r.reasons.empty() ? "" : ": " + r.reasons.front().text;
  const analysis::Measurement* f0 = FindMeasurement(r, analysis::names::kResonanceFHz);
  const std::string f0_text =
      f0 && std::isfinite(f0->value)
          ? "resonance " + Fixed(f0->value, 1) + " Hz, limits " + LimitText(f0->limit) + " Hz"
          : "no resonance measured";
  bool passed = false;
  std::string detail;
  if (master == "good") {
    passed = r.outcome == analysis::Outcome::kPass;
    detail = passed ? who + " passed (" + f0_text + ")"
                    : who + " ended " + outcome + " instead of PASS" + first;
  } else {
    const bool f0_failed = f0 && f0->outcome == analysis::MeasurementOutcome::kFail;
    passed = r.outcome == analysis::Outcome::kFail && f0_failed;
    if (passed)
      detail = who + " rejected on the resonance (" + f0_text + ")";
    else if (r.outcome == analysis::Outcome::kPass)
      detail = who + " PASSed: the station would pass a soft-bonded rotor (" + f0_text + ")";
    else if (r.outcome == analysis::Outcome::kFail)
      detail = who + " FAILed, but not on the resonance (" + f0_text + ")" + first;
    else
      detail = who + " ended " + outcome + " instead of FAIL" + first;
  }
  return {{"master", master}, {"passed", passed}, {"detail", detail}};
}

nlohmann::json LockoutState::ToJson() const {
  if (!enabled) return nullptr;
  return {{"locked", locked},
          {"reason", reason},
          {"good", EntryJson(good)},
          {"limit", EntryJson(limit)},
          {"tests_since_check", tests_since_check}};
}

LockoutState EvaluateLockout(const SelfCheckConfig& c, db::Store& store,
                             std::chrono::system_clock::time_point now) {
  LockoutState s;
  s.enabled = c.enabled();
  if (!s.enabled) return s;
  s.good = store.LatestSelfCheck("good");
  s.limit = store.LatestSelfCheck("limit");
  for (const auto* e : {&s.good, &s.limit}) {
    const std::string master = e == &s.good ? "good" : "limit";
    const std::string serial = e == &s.good ? c.good_master : c.limit_master;
    if (!e->has_value()) {
      s.locked = true;
      s.reason = "no self-check of the " + master + " master " + serial +
                 " yet; test the master to unlock";
      return s;
    }
    if (!(*e)->passed) {
      s.locked = true;
      s.reason = "self-check failed at " + (*e)->at + ": " + (*e)->detail +
                 "; a passing check of the " + master + " master unlocks";
      return s;
    }
  }
  const std::string since = std::min(s.good->at, s.limit->at);
  s.tests_since_check = store.CountTestsSince(db::RecordKind::kProduction, since);
  if (c.every_hours > 0) {
    const auto valid = std::chrono::duration_cast<std::chrono::system_clock::duration>(
        std::chrono::duration<double, std::ratio<3600>>(c.every_hours));
    // One timestamp format: string order is time order (db/clock.h).
    if (since < db::UtcIso8601(now - valid)) {
      s.locked = true;
      char hours[32];
      std::snprintf(hours, sizeof hours, "%g", c.every_hours);
      s.reason = "self-check due: the last check (" + since + ") is older than " + hours +
                 " h; test both masters";
      return s;
    }
  }
  if (c.every_n_tests > 0 && s.tests_since_check >= c.every_n_tests) {
    s.locked = true;
    s.reason = "self-check due: " + std::to_string(s.tests_since_check) +
               " production tests since the last check (" + since + "), every " +
               std::to_string(c.every_n_tests) + " required; test both masters";
  }
  return s;
}

}  // namespace eol::station
