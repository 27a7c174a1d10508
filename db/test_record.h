// The full record of one test: what the store writes, the API serves and the display shows.
// Everything needed to re-judge or audit a test later is here: identity, recipe hash,
// software version, times, conditions, calibration, every measurement with its limits,
// the fit, the verdict with reasons, the raw curves and the sequencer's state trace.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "analysis/qc/measurement.h"
#include "analysis/qc/measurement_json.h"
#include "db/test_conditions.h"

namespace eol::db {

// What was tested (schema v3): a production unit, or a master part that checks the station
// (never in production statistics). Stored as "production" | "self_check" (ToString) in the
// tests.kind column and the record JSON; the schema's CHECK holds the same two strings.
enum class RecordKind { kProduction, kSelfCheck };
inline constexpr std::array kAllRecordKinds = {RecordKind::kProduction, RecordKind::kSelfCheck};
const char* ToString(RecordKind k);
// The kind named `name`; std::invalid_argument "kind: unknown value 'x' (accepted: ...)".
RecordKind ParseRecordKind(std::string_view name);
void to_json(nlohmann::json& j, const RecordKind& k);
void from_json(const nlohmann::json& j, RecordKind& k);

// A curve over frequency (the measured impedance with its sigma, a limit mask, ...).
struct Curve {
  std::string name;  // "impedance", "model", ...
  std::string unit;  // of re/im: "ohm"
  std::vector<double> freq_hz;
  std::vector<double> re;
  std::vector<double> im;
  std::vector<double> sigma;  // may be empty
};

// One sequencer state entered, with the time (ms since the test started) and a detail line.
struct StateEntry {
  std::string state;
  double t_ms = 0.0;
  std::string detail;
};

// Who tested the unit and for which order (schema v4), as given with the serial over HTTP,
// by the line PLC or the scanner (station/daemon/test_request.h says what is accepted). Each is
// empty when not given. In the record's JSON they are the top-level keys "operator_id",
// "shift" and "order_number".
struct WorkContext {
  std::string operator_id;   // the operator's badge or login
  std::string shift;         // the plant's shift name ("A", "night", ...)
  std::string order_number;  // production order or batch
  bool operator==(const WorkContext&) const = default;
};

struct TestRecord {
  std::int64_t id = 0;  // assigned by the store
  std::string serial;
  std::string station_id;
  std::string recipe_id;
  int recipe_version = 0;
  std::string recipe_hash;  // SHA-256 of the recipe's canonical JSON
  std::string software_version;
  std::string started_at;                 // ISO 8601 UTC, millisecond precision
  std::string finished_at;                // empty while the test runs
  std::optional<std::int64_t> retest_of;  // id of the first test of this serial, if any
  // Which test of its serial this is (1: the first, 2: the first retest, ...), counting every
  // stored test of the serial up to this one in id order, whatever its outcome or kind, as the
  // retest limit counts them: set by Store::BeginTest and on every read from the store (the
  // columns decide, not the stored JSON); 0 where unknown (a record from elsewhere).
  int attempt = 0;
  // The tests the recipe allowed this serial in all (recipe "retest.max_tests_per_serial") when
  // it was tested, as the sequencer applied it: "retest 2 of 3" is attempt 2 of max_tests 3.
  // 0: no limit (a master part, a recipe without one) or not recorded (records before it).
  int max_tests = 0;

  analysis::Outcome outcome = analysis::Outcome::kError;
  // Why the outcome is what it is, the decisive first: [{"code", "text"}] in JSON
  // (analysis/qc/measurement.h lists the codes). Old records whose reasons are plain strings
  // read back with the code "legacy".
  std::vector<analysis::Reason> reasons;
  std::vector<analysis::Measurement> measurements;

  // Conditions and context, one typed field per key with its unit (db/test_conditions.h):
  // {"clamp_pressure_bar": 5.1, "phase_pair": 0, "excitation_peak_v": 2.0, ...} in JSON.
  TestConditions conditions;
  nlohmann::json calibration = nlohmann::json::object();
  nlohmann::json fit = nlohmann::json::object();  // the fit summary
  std::vector<Curve> curves;
  std::vector<StateEntry> trace;
  // Where the test's time went, seconds per step (station/daemon/cycle_time.h: "interlocks",
  // "clamp", "excitation", "analysis", ..., and "total"), summed from the trace. The stored
  // record has the steps up to the store (its own store and publish cannot be in it); the
  // record RunTest returns has them all, "total" being serial received -> verdict published.
  std::map<std::string, double> cycle_s;

  RecordKind kind = RecordKind::kProduction;
  // For a self-check: {"master": "good" | "limit", "passed": bool, "detail": "..."}; the store
  // writes it to the self_checks table in the test's own transaction. Empty otherwise.
  nlohmann::json self_check = nlohmann::json::object();
  WorkContext work;  // schema v4
};

void to_json(nlohmann::json& j, const Curve& c);
void from_json(const nlohmann::json& j, Curve& c);
void to_json(nlohmann::json& j, const StateEntry& s);
void from_json(const nlohmann::json& j, StateEntry& s);
void to_json(nlohmann::json& j, const TestRecord& r);
// Throws nlohmann::json::exception naming the field when the JSON is not a record, and
// std::invalid_argument naming the field for an unknown outcome or kind.
void from_json(const nlohmann::json& j, TestRecord& r);

}  // namespace eol::db
