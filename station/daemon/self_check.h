// Station self-checks with master parts, and the lockout they drive.
//
// Two masters are tested like units, by their serials (config "self_check"):
//   good master:  a known good unit; the check passes when its test ends PASS.
//   limit master: a deliberately soft-bonded rotor; the check passes when its test ends FAIL
//                 with the resonance measurement out of limits (the station still sees the
//                 defect it exists to catch).
// Their records are stored with kind "self_check" (never in production statistics) and each
// result goes to the store's self_checks table in the record's own transaction.
//
// Lockout (derived from the stored checks, so it survives a restart): production tests are
// refused with ERROR "station locked out: ..." while
//   - either master has never been checked, or its latest check failed (until it passes), or
//   - the older of the two latest passing checks is more than every_hours old, or
//     every_n_tests production tests have started since it (a check is due).
// Masters themselves are always accepted, and are exempt from the recipe's retest limit.
#pragma once

#include <chrono>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "db/store.h"
#include "db/test_record.h"
#include "station/daemon/config.h"

namespace eol::station {

// "good" or "limit" when `serial` is one of the configured masters; empty otherwise (and
// always when self-checks are off).
std::optional<std::string> MasterRole(const SelfCheckConfig& config, const std::string& serial);

// {"master", "passed", "detail"} for a finished master test (any outcome).
nlohmann::json JudgeMasterTest(const std::string& master, const db::TestRecord& record);

struct LockoutState {
  bool enabled = false;
  bool locked = false;
  std::string reason;                             // why locked; empty when not
  std::optional<db::SelfCheckEntry> good, limit;  // latest check of each master
  int tests_since_check = 0;                      // production tests since the older one
  nlohmann::json ToJson() const;
};

// Reads the store; throws db::StoreError.
LockoutState EvaluateLockout(const SelfCheckConfig& config, db::Store& store,
                             std::chrono::system_clock::time_point now);

}  // namespace eol::station
