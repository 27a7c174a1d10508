#include "db/test_columns.h"

#include <array>
#include <stdexcept>

namespace eol::db {
namespace {

using R = TestRecord;
using V = ColumnValue;
using T = ExportType;
using W = StoreWrite;

V OptInt(const std::optional<std::int64_t>& v) {
  if (!v) return std::monostate{};
  return *v;
}

analysis::Outcome ParseStoredOutcome(const std::string& s) {
  const std::optional<analysis::Outcome> o = analysis::ParseOutcome(s);
  if (!o) throw std::invalid_argument("unknown outcome '" + s + "'");
  return *o;
}

// The record's JSON as the store and the central table hold it: without the curves (the store
// keeps them in their own table, the central table in its `curves` column).
nlohmann::json RecordWithoutCurves(const R& r) {
  nlohmann::json j = r;
  j.erase("curves");
  return j;
}

// Export order (db/export_schema.h): append only; `export_since` says the version.
const std::array kColumns = {
    TestColumn{"id", W::kByStore, "INTEGER", "test_id", "bigint", 1, T::kInteger, "",
               "Test id in the station's database", [](const R& r) -> V { return r.id; },
               [](R& r, const V& v) { r.id = ColumnInt(v); }},
    TestColumn{"serial", W::kAtBegin, "TEXT", "serial", "text", 1, T::kText, "",
               "Serial number of the unit", [](const R& r) -> V { return r.serial; },
               [](R& r, const V& v) { r.serial = ColumnText(v); }},
    TestColumn{"station_id", W::kAtBegin, "TEXT", "station_id", "text", 1, T::kText, "",
               "Station that ran the test", [](const R& r) -> V { return r.station_id; },
               [](R& r, const V& v) { r.station_id = ColumnText(v); }},
    TestColumn{"started_at", W::kAtBegin, "TEXT", "started_at", "timestamptz", 1, T::kTime, "",
               "Start, ISO 8601 UTC with milliseconds",
               [](const R& r) -> V { return r.started_at; },
               [](R& r, const V& v) { r.started_at = ColumnText(v); }},
    TestColumn{"finished_at", W::kAtFinish, "TEXT", "finished_at", "timestamptz", 1, T::kTime, "",
               "End, ISO 8601 UTC with milliseconds", [](const R& r) -> V { return r.finished_at; },
               [](R& r, const V& v) { r.finished_at = ColumnText(v); }},
    TestColumn{"outcome", W::kAtFinish, "TEXT", "outcome", "text", 1, T::kText, "",
               "PASS, FAIL (the motor is out of limits), ERROR (the station could not "
               "measure) or ABORTED",
               [](const R& r) -> V { return std::string(analysis::ToString(r.outcome)); },
               [](R& r, const V& v) { r.outcome = ParseStoredOutcome(ColumnText(v)); }},
    TestColumn{"reason_code", W::kNone, "", "reason_code", "text", 1, T::kText, "",
               "Code of the decisive (first) reason: limit, mask, condition, interlock, "
               "fixture, ...; empty for a clean PASS",
               [](const R& r) -> V {
                 if (r.reasons.empty()) return std::monostate{};
                 return std::string(analysis::ToString(r.reasons.front().code));
               },
               nullptr},
    TestColumn{"reason_text", W::kNone, "", nullptr, nullptr, 1, T::kText, "",
               "Text of the decisive (first) reason",
               [](const R& r) -> V {
                 if (r.reasons.empty()) return std::monostate{};
                 return r.reasons.front().text;
               },
               nullptr},
    TestColumn{"reason_count", W::kNone, "", nullptr, nullptr, 1, T::kInteger, "",
               "Number of reasons the record carries",
               [](const R& r) -> V { return static_cast<std::int64_t>(r.reasons.size()); },
               nullptr},
    TestColumn{"kind", W::kAtBegin, "TEXT", "kind", "text", 1, T::kText, "",
               "production, or self_check (a master part checking the station; never "
               "production statistics)",
               [](const R& r) -> V { return std::string(ToString(r.kind)); },
               [](R& r, const V& v) { r.kind = ParseRecordKind(ColumnText(v)); }},
    TestColumn{"recipe_id", W::kAtBegin, "TEXT", "recipe_id", "text", 1, T::kText, "",
               "Recipe the unit was tested with", [](const R& r) -> V { return r.recipe_id; },
               [](R& r, const V& v) { r.recipe_id = ColumnText(v); }},
    TestColumn{"recipe_version", W::kAtBegin, "INTEGER", "recipe_version", "integer", 1,
               T::kInteger, "", "Its version",
               [](const R& r) -> V { return std::int64_t{r.recipe_version}; },
               [](R& r, const V& v) { r.recipe_version = static_cast<int>(ColumnInt(v)); }},
    TestColumn{"recipe_hash", W::kAtBegin, "TEXT", "recipe_sha256", "text", 1, T::kText, "",
               "SHA-256 of the recipe's canonical JSON",
               [](const R& r) -> V { return r.recipe_hash; },
               [](R& r, const V& v) { r.recipe_hash = ColumnText(v); }},
    TestColumn{"software_version", W::kAtBegin, "TEXT", "software_version", "text", 1, T::kText, "",
               "Station software version and revision",
               [](const R& r) -> V { return r.software_version; },
               [](R& r, const V& v) { r.software_version = ColumnText(v); }},
    TestColumn{"retest_of", W::kByStore, "INTEGER", "retest_of", "bigint", 1, T::kInteger, "",
               "Id of the serial's first test, for a retest",
               [](const R& r) -> V { return OptInt(r.retest_of); },
               [](R& r, const V& v) {
                 r.retest_of.reset();
                 if (!std::holds_alternative<std::monostate>(v)) r.retest_of = ColumnInt(v);
               }},
    TestColumn{"operator_id", W::kAtBegin, "TEXT", "operator_id", "text", 1, T::kText, "",
               "Operator's badge or login, when given",
               [](const R& r) -> V { return r.work.operator_id; },
               [](R& r, const V& v) { r.work.operator_id = ColumnText(v); }},
    TestColumn{"shift", W::kAtBegin, "TEXT", "shift", "text", 1, T::kText, "",
               "Shift name, when given", [](const R& r) -> V { return r.work.shift; },
               [](R& r, const V& v) { r.work.shift = ColumnText(v); }},
    TestColumn{"order_number", W::kAtBegin, "TEXT", "order_number", "text", 1, T::kText, "",
               "Production order or batch, when given",
               [](const R& r) -> V { return r.work.order_number; },
               [](R& r, const V& v) { r.work.order_number = ColumnText(v); }},
    TestColumn{"reasons", W::kAtFinish, "TEXT", "reasons", "jsonb", 0, T::kText, "",
               "Every reason, the decisive first: JSON [{\"code\", \"text\"}]",
               [](const R& r) -> V { return nlohmann::json(r.reasons); },
               [](R& r, const V& v) {
                 r.reasons =
                     nlohmann::json::parse(ColumnText(v)).get<std::vector<analysis::Reason>>();
               }},
    TestColumn{kRecordColumn, W::kAtFinish, "TEXT", "record", "jsonb", 0, T::kText, "",
               "The record's JSON (db/test_record.h) without its curves; in the store NULL "
               "until the test is finished",
               [](const R& r) -> V { return RecordWithoutCurves(r); },
               [](R& r, const V& v) {
                 // An aborted test has no record JSON: its columns are all there is.
                 if (!std::holds_alternative<std::monostate>(v))
                   r = nlohmann::json::parse(ColumnText(v)).get<TestRecord>();
               }},
};

}  // namespace

std::span<const TestColumn> TestColumns() { return kColumns; }

const TestColumn& TestColumnNamed(const std::string& name) {
  for (const TestColumn& c : kColumns)
    if (name == c.name) return c;
  throw std::out_of_range("no test column '" + name + "' (db/test_columns.cc)");
}

std::string ColumnText(const ColumnValue& v) {
  if (std::holds_alternative<std::monostate>(v)) return "";
  if (const auto* s = std::get_if<std::string>(&v)) return *s;
  throw std::invalid_argument("a test column: expected text, got another kind of value");
}

std::int64_t ColumnInt(const ColumnValue& v) {
  if (std::holds_alternative<std::monostate>(v)) return 0;
  if (const auto* i = std::get_if<std::int64_t>(&v)) return *i;
  throw std::invalid_argument("a test column: expected an integer, got another kind of value");
}

}  // namespace eol::db
