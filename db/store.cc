#include "db/store.h"

// Reading the store: queries, self-checks, the audit log and the outbox. Opening it is in
// db/store_open.cc, writing tests in db/store_write.cc.
#include <sqlite3.h>
#include <zlib.h>

#include <algorithm>
#include <stdexcept>
#include <string_view>
#include <utility>

#include "db/curve_codec.h"
#include "db/sqlite_statement.h"
#include "db/store_columns.h"

namespace eol::db {
namespace {

using internal::Message;
using internal::PragmaInt;
using internal::ReadTestRow;
using internal::Statement;
using internal::TestsSelectSql;

constexpr int kMaxQueryLimit = 10000;
// A curve's JSON beyond this size is a corrupt raw_size, not data (100k points are ~10 MB).
constexpr sqlite3_int64 kMaxCurveJsonBytes = sqlite3_int64{1} << 30;

// ---- Reading -----------------------------------------------------------------------------

std::string Decompress(std::string_view packed, std::int64_t raw_size, const std::string& path,
                       const std::string& op) {
  if (raw_size < 0 || raw_size > kMaxCurveJsonBytes)
    throw StoreError(Message(path, op, "implausible raw_size " + std::to_string(raw_size)));
  std::string raw(static_cast<std::size_t>(raw_size), '\0');
  uLongf size = static_cast<uLongf>(raw_size);
  const int rc =
      uncompress(reinterpret_cast<Bytef*>(raw.data()), &size,
                 reinterpret_cast<const Bytef*>(packed.data()), static_cast<uLong>(packed.size()));
  if (rc != Z_OK)
    throw StoreError(
        Message(path, op, std::string("corrupt curve data (zlib: ") + zError(rc) + ")"));
  if (size != static_cast<uLongf>(raw_size))
    throw StoreError(Message(path, op,
                             "corrupt curve data (" + std::to_string(size) +
                                 " bytes, raw_size says " + std::to_string(raw_size) + ")"));
  return raw;
}

void LoadCurves(Statement& c, const std::string& path, TestRecord& r) {
  c.Reset();
  c.BindInt(1, r.id);
  while (c.Step()) {
    const std::string op = "read curve '" + c.Text(0) + "' of test " + std::to_string(r.id);
    if (c.Text(3) == "binary-v1") {
      try {
        r.curves.push_back(DecodeCurve(c.Blob(2), c.Text(0)));
      } catch (const std::invalid_argument& e) {
        throw StoreError(Message(path, op, std::string("corrupt curve data: ") + e.what()));
      }
      continue;
    }
    const std::string raw = Decompress(c.Blob(2), c.Int(1), path, op);
    try {
      r.curves.push_back(nlohmann::json::parse(raw).get<Curve>());
    } catch (const nlohmann::json::exception& e) {
      throw StoreError(Message(path, op, std::string("stored JSON is not a curve: ") + e.what()));
    }
  }
}

// Steps `s` (a TestsSelectSql() query with its parameters bound) to the end.
std::vector<TestRecord> ReadTests(sqlite3* db, const std::string& path, Statement& s,
                                  bool with_curves) {
  std::vector<TestRecord> out;
  while (s.Step()) out.push_back(ReadTestRow(s, path));
  if (with_curves && !out.empty()) {
    Statement c(db, path,
                "SELECT name, raw_size, data, encoding FROM curves WHERE test_id = ?1 ORDER BY id",
                "read curves");
    for (TestRecord& r : out) LoadCurves(c, path, r);
  }
  return out;
}

}  // namespace

std::vector<TestRecord> Store::TestsOfSerial(const std::string& serial, bool with_curves) {
  Statement s(db_, path_,
              TestsSelectSql() +
                  "WHERE serial = ?1 AND outcome <> 'RUNNING' ORDER BY started_at DESC, id DESC",
              "tests of serial '" + serial + "'");
  s.BindText(1, serial);
  return ReadTests(db_, path_, s, with_curves);
}

std::optional<TestRecord> Store::LatestOfSerial(const std::string& serial) {
  Statement s(db_, path_,
              TestsSelectSql() +
                  "WHERE serial = ?1 AND outcome <> 'RUNNING' "
                  "ORDER BY started_at DESC, id DESC LIMIT 1",
              "latest test of serial '" + serial + "'");
  s.BindText(1, serial);
  std::vector<TestRecord> found = ReadTests(db_, path_, s, /*with_curves=*/true);
  if (found.empty()) return std::nullopt;
  return std::move(found.front());
}

std::optional<TestRecord> Store::Test(std::int64_t id, bool with_curves) {
  Statement s(db_, path_, TestsSelectSql() + "WHERE id = ?1 AND outcome <> 'RUNNING'",
              "read test " + std::to_string(id));
  s.BindInt(1, id);
  std::vector<TestRecord> found = ReadTests(db_, path_, s, with_curves);
  if (found.empty()) return std::nullopt;
  return std::move(found.front());
}

std::vector<TestRecord> Store::Tests(const TestQuery& query) {
  // Only fixed clauses are appended; every value is a bound parameter.
  std::string sql = TestsSelectSql() + "WHERE outcome <> 'RUNNING'";
  int n = 0;
  const int from_i = query.from ? ++n : 0;
  if (from_i) sql += " AND started_at >= ?" + std::to_string(from_i);
  const int to_i = query.to ? ++n : 0;
  if (to_i) sql += " AND started_at < ?" + std::to_string(to_i);
  const int outcome_i = query.outcome ? ++n : 0;
  if (outcome_i) sql += " AND outcome = ?" + std::to_string(outcome_i);
  const int serial_i = query.serial ? ++n : 0;
  if (serial_i) sql += " AND serial = ?" + std::to_string(serial_i);
  const int order_i = query.order_number ? ++n : 0;
  if (order_i) sql += " AND order_number = ?" + std::to_string(order_i);
  const int after_i = query.after ? ++n : 0;
  if (after_i) {
    ++n;  // the id's parameter
    sql += " AND (started_at < ?" + std::to_string(after_i) + " OR (started_at = ?" +
           std::to_string(after_i) + " AND id < ?" + std::to_string(after_i + 1) + "))";
  }
  const int limit_i = ++n;
  sql += " ORDER BY started_at DESC, id DESC LIMIT ?" + std::to_string(limit_i);

  Statement s(db_, path_, sql, "query tests");
  if (from_i) s.BindText(from_i, *query.from);
  if (to_i) s.BindText(to_i, *query.to);
  if (outcome_i) s.BindText(outcome_i, analysis::ToString(*query.outcome));
  if (serial_i) s.BindText(serial_i, *query.serial);
  if (order_i) s.BindText(order_i, *query.order_number);
  if (after_i) {
    s.BindText(after_i, query.after->first);
    s.BindInt(after_i + 1, query.after->second);
  }
  s.BindInt(limit_i, std::clamp(query.limit, 1, kMaxQueryLimit));
  return ReadTests(db_, path_, s, query.with_curves);
}

std::string Store::IntegrityCheck() {
  Statement s(db_, path_, "PRAGMA integrity_check", "integrity check");
  if (!s.Step()) throw StoreError(Message(path_, "integrity check", "no result"));
  return s.Text(0);
}

int Store::CountRunning() {
  return static_cast<int>(PragmaInt(
      db_, path_, "SELECT count(*) FROM tests WHERE outcome = 'RUNNING'", "count running tests"));
}

namespace {

SelfCheckEntry RowToSelfCheck(const Statement& s) {
  SelfCheckEntry e;
  e.test_id = s.Int(0);
  e.at = s.Text(1);
  e.station_id = s.Text(2);
  e.master = s.Text(3);
  e.serial = s.Text(4);
  e.passed = s.Int(5) != 0;
  e.detail = s.Text(6);
  return e;
}

constexpr std::string_view kSelectSelfChecks =
    "SELECT test_id, at, station_id, master, serial, passed, detail FROM self_checks ";

}  // namespace

std::vector<SelfCheckEntry> Store::SelfChecks(int limit) {
  Statement s(db_, path_, std::string(kSelectSelfChecks) + "ORDER BY id DESC LIMIT ?1",
              "read the self-checks");
  s.BindInt(1, std::clamp(limit, 1, kMaxQueryLimit));
  std::vector<SelfCheckEntry> out;
  while (s.Step()) out.push_back(RowToSelfCheck(s));
  return out;
}

std::optional<SelfCheckEntry> Store::LatestSelfCheck(const std::string& master) {
  Statement s(db_, path_,
              std::string(kSelectSelfChecks) + "WHERE master = ?1 ORDER BY id DESC LIMIT 1",
              "read the latest self-check of the " + master + " master");
  s.BindText(1, master);
  if (!s.Step()) return std::nullopt;
  return RowToSelfCheck(s);
}

int Store::CountTestsSince(RecordKind kind, const std::string& since) {
  Statement s(db_, path_,
              "SELECT count(*) FROM tests WHERE kind = ?1 AND started_at >= ?2 "
              "AND outcome <> 'RUNNING'",
              std::string("count ") + ToString(kind) + " tests since " + since);
  s.BindText(1, ToString(kind));
  s.BindText(2, since);
  if (!s.Step()) throw StoreError(Message(path_, "count tests", "no result"));
  return static_cast<int>(s.Int(0));
}

std::vector<OutcomeRow> Store::OutcomeRows(const OutcomeQuery& q) {
  // Only fixed clauses are appended; every value is a bound parameter.
  static const internal::TestColumnSet kColumns{
      "id",        "serial",         "started_at",  "outcome", "retest_of",
      "recipe_id", "recipe_version", "recipe_hash", "reasons"};
  std::string sql =
      "SELECT " + kColumns.List() + " FROM tests WHERE outcome <> 'RUNNING' AND kind = ?1";
  int n = 1;
  const int from_i = q.from ? ++n : 0;
  if (from_i) sql += " AND started_at >= ?" + std::to_string(from_i);
  const int to_i = q.to ? ++n : 0;
  if (to_i) sql += " AND started_at < ?" + std::to_string(to_i);
  const int hash_i = q.recipe_hash ? ++n : 0;
  if (hash_i) sql += " AND recipe_hash = ?" + std::to_string(hash_i);
  sql += " ORDER BY started_at, id LIMIT 1000000";
  Statement s(db_, path_, sql, "read outcomes for yield");
  s.BindText(1, ToString(q.kind));
  if (from_i) s.BindText(from_i, *q.from);
  if (to_i) s.BindText(to_i, *q.to);
  if (hash_i) s.BindText(hash_i, *q.recipe_hash);
  std::vector<OutcomeRow> out;
  TestRecord t;  // the columns' fields, overwritten by each row
  while (s.Step()) {
    kColumns.Read(s, 0, path_, "read the outcome of test " + std::to_string(s.Int(0)), t);
    out.push_back({t.id, std::move(t.serial), std::move(t.started_at), t.outcome, t.retest_of,
                   std::move(t.recipe_id), t.recipe_version, std::move(t.recipe_hash),
                   std::move(t.reasons)});
  }
  return out;
}

std::vector<MeasurementRow> Store::MeasurementRows(const MeasurementQuery& q) {
  // Only fixed clauses are appended; every value is a bound parameter.
  static const internal::TestColumnSet kColumns{
      "id", "serial", "started_at", "outcome", "recipe_id", "recipe_version", "recipe_hash"};
  std::string sql = "SELECT " + kColumns.List("t.") +
                    ", m.name, m.unit, m.value, m.lo, m.hi FROM measurements m "
                    "JOIN tests t ON t.id = m.test_id WHERE t.outcome IN ('PASS', 'FAIL', 'ERROR') "
                    "AND t.kind = ?1";
  int n = 1;
  const int from_i = q.from ? ++n : 0;
  if (from_i) sql += " AND t.started_at >= ?" + std::to_string(from_i);
  const int to_i = q.to ? ++n : 0;
  if (to_i) sql += " AND t.started_at < ?" + std::to_string(to_i);
  const int hash_i = q.recipe_hash ? ++n : 0;
  if (hash_i) sql += " AND t.recipe_hash = ?" + std::to_string(hash_i);
  const int serial_i = q.serial ? ++n : 0;
  if (serial_i) sql += " AND t.serial = ?" + std::to_string(serial_i);
  sql += " ORDER BY t.started_at, t.id, m.id LIMIT 1000000";
  Statement s(db_, path_, sql, "read measurements for statistics");
  s.BindText(1, ToString(q.kind));
  if (from_i) s.BindText(from_i, *q.from);
  if (to_i) s.BindText(to_i, *q.to);
  if (hash_i) s.BindText(hash_i, *q.recipe_hash);
  if (serial_i) s.BindText(serial_i, *q.serial);
  std::vector<MeasurementRow> out;
  TestRecord t;  // the columns' fields, overwritten by each row
  const int m = kColumns.size();
  const std::string op = "read measurements for statistics";
  while (s.Step()) {
    kColumns.Read(s, 0, path_, op, t);
    out.push_back({t.id, std::move(t.serial), std::move(t.started_at), t.outcome,
                   std::move(t.recipe_id), t.recipe_version, std::move(t.recipe_hash), s.Text(m),
                   s.Text(m + 1), s.OptReal(m + 2), s.OptReal(m + 3), s.OptReal(m + 4)});
  }
  return out;
}

std::vector<RecipeAudit> Store::AuditLog(int limit) {
  Statement s(db_, path_,
              "SELECT at, who, role, recipe_id, old_version, new_version, old_hash, new_hash, "
              "path FROM recipe_audit ORDER BY id DESC LIMIT ?1",
              "read the recipe audit log");
  s.BindInt(1, std::clamp(limit, 1, 10000));
  std::vector<RecipeAudit> out;
  while (s.Step()) {
    RecipeAudit a;
    a.at = s.Text(0);
    a.who = s.Text(1);
    a.role = s.Text(2);
    a.recipe_id = s.Text(3);
    if (!s.IsNull(4)) a.old_version = static_cast<int>(s.Int(4));
    a.new_version = static_cast<int>(s.Int(5));
    a.old_hash = s.IsNull(6) ? "" : s.Text(6);
    a.new_hash = s.Text(7);
    a.path = s.Text(8);
    out.push_back(a);
  }
  return out;
}

// ---- Outbox ------------------------------------------------------------------------------

std::vector<OutboxEntry> Store::OutboxAfterCursor(const std::string& consumer, int limit) {
  Statement s(db_, path_,
              "SELECT id, test_id, created_at FROM outbox WHERE id > "
              "coalesce((SELECT last_id FROM outbox_cursors WHERE consumer = ?1), 0) "
              "ORDER BY id LIMIT ?2",
              "read the outbox of '" + consumer + "'");
  s.BindText(1, consumer);
  s.BindInt(2, std::clamp(limit, 1, kMaxQueryLimit));
  std::vector<OutboxEntry> out;
  while (s.Step()) out.push_back({s.Int(0), s.Int(1), s.Text(2)});
  return out;
}

void Store::AdvanceOutboxCursor(const std::string& consumer, std::int64_t id) {
  Statement s(db_, path_,
              "INSERT INTO outbox_cursors (consumer, last_id) VALUES (?1, ?2) "
              "ON CONFLICT (consumer) DO UPDATE SET last_id = max(last_id, excluded.last_id)",
              "advance the outbox cursor of '" + consumer + "' to " + std::to_string(id));
  s.BindText(1, consumer);
  s.BindInt(2, id);
  s.Run();
}

std::int64_t Store::OutboxCursor(const std::string& consumer) {
  Statement s(db_, path_, "SELECT last_id FROM outbox_cursors WHERE consumer = ?1",
              "read the outbox cursor of '" + consumer + "'");
  s.BindText(1, consumer);
  return s.Step() ? s.Int(0) : 0;
}

std::int64_t Store::OutboxPending(const std::string& consumer) {
  Statement s(db_, path_,
              "SELECT count(*) FROM outbox WHERE id > "
              "coalesce((SELECT last_id FROM outbox_cursors WHERE consumer = ?1), 0)",
              "count the outbox of '" + consumer + "'");
  s.BindText(1, consumer);
  return s.Step() ? s.Int(0) : 0;
}

}  // namespace eol::db
