// Writing tests: begin, finish, import; what a failed write leaves behind; the checkpoint and
// the last-verdict file after each verdict (contract in db/store.h).
#include <tuple>
#include <utility>

#include "db/clock.h"
#include "db/curve_codec.h"
#include "db/last_verdict.h"
#include "db/sqlite_statement.h"
#include "db/store.h"
#include "db/store_columns.h"

namespace eol::db {
namespace {

using internal::BindBeginColumns;
using internal::BindFinishColumns;
using internal::Exec;
using internal::kBusyTimeoutMs;
using internal::Message;
using internal::Statement;
using internal::TestsFinishSql;
using internal::TestsInsertSql;
using internal::Transaction;

// How long the checkpoint after a verdict waits for readers of an older snapshot (an export
// in progress) before it leaves the copy to the next verdict's checkpoint. The verdict is
// durable in the WAL and noted in "<path>.last-verdict" either way; this only bounds how long
// the publication of the verdict can be held up by a reader.
constexpr int kCheckpointWaitMs = 500;

// `id_floor`: the new test's id is at least this (Store::id_floor_); 0: max(id) + 1, as SQLite.
void InsertTestRow(sqlite3* db, const std::string& path, TestRecord& record,
                   std::int64_t id_floor) {
  const std::string op = "begin the test of serial '" + record.serial + "'";
  if (record.serial.empty()) throw StoreError(Message(path, op, "record.serial is empty"));
  if (record.started_at.empty()) throw StoreError(Message(path, op, "record.started_at is empty"));
  Statement s(db, path, TestsInsertSql(), op);
  s.BindInt(1, id_floor);
  s.BindText(2, record.serial);
  BindBeginColumns(s, record);
  if (!s.Step()) throw StoreError(Message(path, op, "the insert returned no id"));
  const std::int64_t id = s.Int(0);
  const std::optional<std::int64_t> retest_of = s.OptInt(1);
  s.Run();  // completes the statement (and, outside a transaction, commits it)
  Statement count(db, path, "SELECT count(*) FROM tests WHERE serial = ?1 AND id <= ?2", op);
  count.BindText(1, record.serial);
  count.BindInt(2, id);
  if (!count.Step()) throw StoreError(Message(path, op, "counting the serial's tests failed"));
  record.id = id;
  record.retest_of = retest_of;
  record.attempt = static_cast<int>(count.Int(0));
}

// The caller holds the transaction.
void WriteFinish(sqlite3* db, const std::string& path, const TestRecord& record) {
  const std::string op = "finish test " + std::to_string(record.id);
  if (record.finished_at.empty())
    throw StoreError(Message(path, op, "record.finished_at is empty"));
  {
    Statement s(db, path, TestsFinishSql(), op);
    s.BindInt(1, record.id);
    BindFinishColumns(s, record);
    s.Run();
  }
  if (sqlite3_changes(db) != 1) {
    Statement s(db, path, "SELECT outcome FROM tests WHERE id = ?1", op);
    s.BindInt(1, record.id);
    throw StoreError(Message(
        path, op,
        s.Step() ? "the test is " + s.Text(0) + ", not RUNNING (a test is finished only once)"
                 : std::string("no such test (record.id must come from BeginTest)")));
  }

  Statement m(db, path, R"sql(
    INSERT INTO measurements (test_id, name, value, sigma, unit, lo, hi, outcome, marginal)
    VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9))sql",
              op + " (write measurements)");
  for (const analysis::Measurement& x : record.measurements) {
    m.Reset();
    m.BindInt(1, record.id);
    m.BindText(2, x.name);
    m.BindReal(3, x.value);
    m.BindReal(4, x.sigma);
    m.BindText(5, x.unit);
    m.BindReal(6, x.limit.lo);
    m.BindReal(7, x.limit.hi);
    m.BindText(8, analysis::ToString(x.outcome));
    m.BindInt(9, x.marginal ? 1 : 0);
    m.Run();
  }

  if (record.kind == RecordKind::kSelfCheck) {
    const nlohmann::json& c = record.self_check;
    const std::string check_op = op + " (write the self-check)";
    if (!c.is_object() || !c.contains("master") || !c["master"].is_string() ||
        !c.contains("passed") || !c["passed"].is_boolean())
      throw StoreError(Message(path, check_op, "record.self_check needs master and passed"));
    Statement sc(
        db, path,
        "INSERT INTO self_checks (test_id, at, station_id, master, serial, passed, detail) "
        "VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7)",
        check_op);
    sc.BindInt(1, record.id);
    sc.BindText(2, record.finished_at);
    sc.BindText(3, record.station_id);
    sc.BindText(4, c["master"].get<std::string>());
    sc.BindText(5, record.serial);
    sc.BindInt(6, c["passed"].get<bool>() ? 1 : 0);
    sc.BindText(7, c.value("detail", ""));
    sc.Run();
  }

  {
    Statement o(db, path, "INSERT INTO outbox (test_id, created_at) VALUES (?1, ?2)",
                op + " (queue in the outbox)");
    o.BindInt(1, record.id);
    o.BindText(2, record.finished_at);
    o.Run();
  }

  const std::string curves_op = op + " (write curves)";
  Statement c(db, path,
              "INSERT INTO curves (test_id, name, raw_size, data, encoding) "
              "VALUES (?1, ?2, ?3, ?4, 'binary-v1')",
              curves_op);
  for (const Curve& curve : record.curves) {
    std::string packed;
    try {
      packed = EncodeCurve(curve);
    } catch (const std::invalid_argument& e) {
      throw StoreError(Message(path, curves_op, e.what()));
    }
    c.Reset();
    c.BindInt(1, record.id);
    c.BindText(2, curve.name);
    c.BindInt(3, static_cast<std::int64_t>(packed.size()));
    c.BindBlob(4, packed.data(), packed.size());
    c.Run();
  }
}

// Finishes test `id`, still RUNNING after its FinishTest failed with `failure`, as ERROR and
// queues it in the outbox, as the recovery at open does; false when it is not RUNNING.
bool FinishAsError(sqlite3* db, const std::string& path, std::int64_t id,
                   const std::string& failure, const std::string& now) {
  const std::string op = "finish test " + std::to_string(id) + " as ERROR after a failed write";
  {
    Statement s(db, path,
                "UPDATE tests SET outcome = 'ERROR', finished_at = ?2, reasons = ?3 "
                "WHERE id = ?1 AND outcome = 'RUNNING'",
                op);
    s.BindInt(1, id);
    s.BindText(2, now);
    s.BindText(3, nlohmann::json::array({analysis::Reason{analysis::ReasonCode::kStore,
                                                          "store write failed: " + failure}})
                      .dump());
    s.Run();
  }
  if (sqlite3_changes(db) != 1) return false;
  Statement o(db, path, "INSERT INTO outbox (test_id, created_at) VALUES (?1, ?2)",
              op + " (queue in the outbox)");
  o.BindInt(1, id);
  o.BindText(2, now);
  o.Run();
  return true;
}

}  // namespace

void Store::FinishFailedWrites() {
  if (failed_finishes_.empty()) return;
  Transaction tx(db_, path_, "finish as ERROR the tests whose record could not be stored");
  const std::string now = UtcNowIso8601();
  for (const auto& [id, failure] : failed_finishes_) FinishAsError(db_, path_, id, failure, now);
  tx.Commit();
  failed_finishes_.clear();
}

void Store::Failed(const StoreError& e) { write_failure_ = e.what(); }

// The verdict is committed: copy it into the database file and note it in the last-verdict
// file. Neither throws (the verdict is stored); a failure is kept in write_failure_.
void Store::AfterVerdict(const TestRecord& record) {
  if (checkpoint_each_test_) {
    int log_frames = 0, copied = 0;
    sqlite3_busy_timeout(db_, kCheckpointWaitMs);
    const int rc =
        sqlite3_wal_checkpoint_v2(db_, nullptr, SQLITE_CHECKPOINT_TRUNCATE, &log_frames, &copied);
    sqlite3_busy_timeout(db_, kBusyTimeoutMs);
    // SQLITE_BUSY: a reader of an older snapshot; the next verdict's checkpoint copies this one.
    if (rc != SQLITE_OK && (rc & 0xff) != SQLITE_BUSY)
      write_failure_ = Message(path_, "checkpoint after test " + std::to_string(record.id),
                               std::string(sqlite3_errmsg(db_)) + " (sqlite code " +
                                   std::to_string(rc) + "); the verdict is in the WAL only");
  }
  if (verdict_fd_ < 0) return;
  const std::string failed =
      WriteLastVerdict(verdict_fd_, {record.id, std::string(analysis::ToString(record.outcome)),
                                     record.finished_at, record.serial});
  if (!failed.empty())
    write_failure_ =
        Message(path_, "note test " + std::to_string(record.id) + " in " + LastVerdictPath(path_),
                failed + "; a later loss of this verdict would not be named");
}

void Store::BeginTest(TestRecord& record) {
  try {
    FinishFailedWrites();
    InsertTestRow(db_, path_, record, id_floor_);
  } catch (const StoreError& e) {
    Failed(e);
    throw;
  }
  write_failure_.clear();
}

void Store::FinishTest(const TestRecord& record) {
  try {
    FinishFailedWrites();
    Transaction tx(db_, path_, "finish test " + std::to_string(record.id));
    WriteFinish(db_, path_, record);
    tx.Commit();
  } catch (const StoreError& e) {
    // Rolled back. The test must not stay RUNNING until the next restart: finish it as
    // ERROR now, or, when that cannot be written either, before the next write.
    Failed(e);
    failed_finishes_.emplace_back(record.id, e.what());
    try {
      FinishFailedWrites();
    } catch (const StoreError&) {
      // Still failing: BeginTest (and every other write) tries again first.
    }
    throw;
  }
  write_failure_.clear();
  AfterVerdict(record);
}

void Store::Insert(TestRecord& record) {
  const std::int64_t id = record.id;
  const std::optional<std::int64_t> retest_of = record.retest_of;
  const int attempt = record.attempt;
  try {
    FinishFailedWrites();
    // One transaction: an import is either fully there or not at all (never left RUNNING).
    Transaction tx(db_, path_, "insert the test of serial '" + record.serial + "'");
    InsertTestRow(db_, path_, record, id_floor_);
    WriteFinish(db_, path_, record);
    tx.Commit();
  } catch (const StoreError& e) {
    // Rolled back: the record must not carry an id that is not in the file.
    record.id = id;
    record.retest_of = retest_of;
    record.attempt = attempt;
    Failed(e);
    throw;
  }
  write_failure_.clear();
  AfterVerdict(record);
}

void Store::InsertAll(std::vector<TestRecord>& records) {
  std::vector<std::pair<std::int64_t, std::optional<std::int64_t>>> before;
  before.reserve(records.size());
  for (const TestRecord& r : records) before.emplace_back(r.id, r.retest_of);
  try {
    FinishFailedWrites();
    Transaction tx(db_, path_, "insert " + std::to_string(records.size()) + " tests");
    for (TestRecord& r : records) {
      InsertTestRow(db_, path_, r, id_floor_);
      WriteFinish(db_, path_, r);
    }
    tx.Commit();
  } catch (const StoreError& e) {
    for (std::size_t i = 0; i < records.size(); ++i)
      std::tie(records[i].id, records[i].retest_of) = before[i];
    Failed(e);
    throw;
  }
  write_failure_.clear();
  if (!records.empty()) AfterVerdict(records.back());
}

void Store::AppendAudit(const RecipeAudit& a) {
  Statement s(db_, path_,
              "INSERT INTO recipe_audit (at, who, role, recipe_id, old_version, new_version, "
              "old_hash, new_hash, path) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9)",
              "append to the recipe audit log");
  s.BindText(1, a.at);
  s.BindText(2, a.who);
  s.BindText(3, a.role);
  s.BindText(4, a.recipe_id);
  if (a.old_version)
    s.BindInt(5, *a.old_version);
  else
    s.BindNull(5);
  s.BindInt(6, a.new_version);
  if (a.old_hash.empty())
    s.BindNull(7);
  else
    s.BindText(7, a.old_hash);
  s.BindText(8, a.new_hash);
  s.BindText(9, a.path);
  try {
    FinishFailedWrites();
    s.Run();
  } catch (const StoreError& e) {
    Failed(e);
    throw;
  }
  write_failure_.clear();
}
}  // namespace eol::db
