#include "db/store.h"

#include <fcntl.h>
#include <sqlite3.h>
#include <sys/file.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <string_view>
#include <tuple>
#include <utility>

#include "db/clock.h"
#include "db/curve_codec.h"
#include "db/schema.h"

namespace eol::db {
namespace {

// How long a writer waits for another connection's lock before the operation fails.
constexpr int kBusyTimeoutMs = 5000;
constexpr int kMaxQueryLimit = 10000;
// A curve's JSON beyond this size is a corrupt raw_size, not data (100k points are ~10 MB).
constexpr sqlite3_int64 kMaxCurveJsonBytes = sqlite3_int64{1} << 30;
constexpr const char* kInterruptedReason = "interrupted: station stopped before the test finished";

std::string Message(const std::string& path, const std::string& op, const std::string& detail) {
  return "store '" + path + "': " + op + ": " + detail;
}

// The connection's last error; for a lock, also how long SQLite was allowed to wait for it.
[[noreturn]] void ThrowSqlite(sqlite3* db, const std::string& path, const std::string& op) {
  std::string detail = sqlite3_errmsg(db);
  const int rc = sqlite3_extended_errcode(db);
  detail += " (sqlite code " + std::to_string(rc) + ")";
  if ((rc & 0xff) == SQLITE_BUSY || (rc & 0xff) == SQLITE_LOCKED)
    detail += "; busy timeout " + std::to_string(kBusyTimeoutMs) + " ms";
  throw StoreError(Message(path, op, detail));
}

// Runs SQL without parameters (PRAGMAs with constant values, transaction control, DDL).
void Exec(sqlite3* db, const std::string& path, const char* sql, const std::string& op) {
  if (sqlite3_exec(db, sql, nullptr, nullptr, nullptr) != SQLITE_OK) ThrowSqlite(db, path, op);
}

// One prepared statement, finalised when it goes out of scope. Errors name `op`.
class Statement {
 public:
  Statement(sqlite3* db, const std::string& path, std::string_view sql, std::string op)
      : db_(db), path_(path), op_(std::move(op)) {
    if (sqlite3_prepare_v2(db_, sql.data(), static_cast<int>(sql.size()), &stmt_, nullptr) !=
        SQLITE_OK)
      ThrowSqlite(db_, path_, op_);
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  void BindNull(int i) { Check(sqlite3_bind_null(stmt_, i)); }
  void BindInt(int i, std::int64_t v) { Check(sqlite3_bind_int64(stmt_, i, v)); }
  // Not finite -> NULL, as in the record's JSON.
  void BindReal(int i, double v) {
    if (std::isfinite(v))
      Check(sqlite3_bind_double(stmt_, i, v));
    else
      BindNull(i);
  }
  void BindReal(int i, const std::optional<double>& v) {
    if (v)
      BindReal(i, *v);
    else
      BindNull(i);
  }
  void BindText(int i, std::string_view v) {
    // A null pointer would bind NULL; an empty string must stay an empty string.
    Check(sqlite3_bind_text64(stmt_, i, v.data() != nullptr ? v.data() : "", v.size(),
                              SQLITE_TRANSIENT, SQLITE_UTF8));
  }
  void BindBlob(int i, const void* data, std::size_t size) {
    Check(sqlite3_bind_blob64(stmt_, i, data, size, SQLITE_TRANSIENT));
  }

  // True when a row is ready, false when the statement is done.
  bool Step() {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    ThrowSqlite(db_, path_, op_);
  }
  void Run() {
    while (Step()) {
    }
  }
  void Reset() {
    sqlite3_reset(stmt_);
    sqlite3_clear_bindings(stmt_);
  }

  bool IsNull(int c) const { return sqlite3_column_type(stmt_, c) == SQLITE_NULL; }
  std::int64_t Int(int c) const { return sqlite3_column_int64(stmt_, c); }
  std::optional<std::int64_t> OptInt(int c) const {
    return IsNull(c) ? std::nullopt : std::optional<std::int64_t>(Int(c));
  }
  std::optional<double> OptReal(int c) const {
    return IsNull(c) ? std::nullopt : std::optional<double>(sqlite3_column_double(stmt_, c));
  }
  // NULL -> "".
  std::string Text(int c) const {
    const auto* p = reinterpret_cast<const char*>(sqlite3_column_text(stmt_, c));
    const int n = sqlite3_column_bytes(stmt_, c);
    return p != nullptr ? std::string(p, static_cast<std::size_t>(n)) : std::string();
  }
  std::string_view Blob(int c) const {
    const auto* p = static_cast<const char*>(sqlite3_column_blob(stmt_, c));
    const int n = sqlite3_column_bytes(stmt_, c);
    return p != nullptr ? std::string_view(p, static_cast<std::size_t>(n)) : std::string_view();
  }

 private:
  void Check(int rc) {
    if (rc != SQLITE_OK) ThrowSqlite(db_, path_, op_);
  }

  sqlite3* db_;
  const std::string& path_;
  std::string op_;
  sqlite3_stmt* stmt_ = nullptr;
};

// BEGIN IMMEDIATE (takes the write lock now, so the transaction cannot fail half-way for a
// lock); rolled back unless committed.
class Transaction {
 public:
  Transaction(sqlite3* db, const std::string& path, std::string op)
      : db_(db), path_(path), op_(std::move(op)) {
    Exec(db_, path_, "BEGIN IMMEDIATE", op_ + ": begin transaction");
  }
  ~Transaction() {
    if (!committed_) sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
  }
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;

  // Durable when it returns (WAL with synchronous=FULL syncs the log on commit).
  void Commit() {
    Exec(db_, path_, "COMMIT", op_ + ": commit");
    committed_ = true;
  }

 private:
  sqlite3* db_;
  const std::string& path_;
  std::string op_;
  bool committed_ = false;
};

// ---- Schema ------------------------------------------------------------------------------

// kMigrations[n] takes the schema from user_version n to n + 1, inside the caller's
// transaction. Append, never edit: see db/schema.h.
using Migration = void (*)(sqlite3* db, const std::string& path);

void MigrateTo1(sqlite3* db, const std::string& path) {
  Exec(db, path, schema::kSchemaV1, "migrate the schema to version 1");
}

void MigrateTo2(sqlite3* db, const std::string& path) {
  Exec(db, path, schema::kSchemaV2, "migrate the schema to version 2");
}

void MigrateTo3(sqlite3* db, const std::string& path) {
  Exec(db, path, schema::kSchemaV3, "migrate the schema to version 3");
}

void MigrateTo4(sqlite3* db, const std::string& path) {
  Exec(db, path, schema::kSchemaV4, "migrate the schema to version 4");
}

void MigrateTo5(sqlite3* db, const std::string& path) {
  Exec(db, path, schema::kSchemaV5, "migrate the schema to version 5");
}

void MigrateTo6(sqlite3* db, const std::string& path) {
  Exec(db, path, schema::kSchemaV6, "migrate the schema to version 6");
}

constexpr std::array<Migration, Store::kSchemaVersion> kMigrations = {
    &MigrateTo1, &MigrateTo2, &MigrateTo3, &MigrateTo4, &MigrateTo5, &MigrateTo6};

std::int64_t PragmaInt(sqlite3* db, const std::string& path, const char* sql,
                       const std::string& op) {
  Statement s(db, path, sql, op);
  if (!s.Step()) throw StoreError(Message(path, op, "no result"));
  return s.Int(0);
}

void Configure(sqlite3* db, const std::string& path) {
  sqlite3_extended_result_codes(db, 1);
  sqlite3_busy_timeout(db, kBusyTimeoutMs);
  {
    // The first statement reads the file: a file that is not a database fails here.
    const std::string op = "open (PRAGMA journal_mode = WAL)";
    Statement s(db, path, "PRAGMA journal_mode = WAL", op);
    const std::string mode = s.Step() ? s.Text(0) : std::string();
    if (mode != "wal")
      throw StoreError(Message(path, op, "the journal mode stayed '" + mode + "', not 'wal'"));
  }
  Exec(db, path, "PRAGMA synchronous = FULL", "open (PRAGMA synchronous = FULL)");
  Exec(db, path, "PRAGMA foreign_keys = ON", "open (PRAGMA foreign_keys = ON)");
  if (PragmaInt(db, path, "PRAGMA foreign_keys", "open (PRAGMA foreign_keys)") != 1)
    throw StoreError(Message(path, "open", "this SQLite cannot enforce foreign keys"));
}

// Refuses files that are not ours or were written by newer software.
void CheckSchemaVersion(sqlite3* db, const std::string& path, std::int64_t version) {
  const std::int64_t app_id =
      PragmaInt(db, path, "PRAGMA application_id", "open (read the application id)");
  if ((version > 0 && app_id != schema::kApplicationId) ||
      (version == 0 && app_id != 0 && app_id != schema::kApplicationId))
    throw StoreError(Message(path, "open",
                             "not an EOL test store (application_id " + std::to_string(app_id) +
                                 ", user_version " + std::to_string(version) + ")"));
  if (version > Store::kSchemaVersion)
    throw StoreError(Message(path, "open",
                             "the file has schema version " + std::to_string(version) +
                                 ", newer than this software knows (version " +
                                 std::to_string(Store::kSchemaVersion) +
                                 "); update the station software to use it"));
}

void Migrate(sqlite3* db, const std::string& path) {
  constexpr const char* kReadVersion = "PRAGMA user_version";
  const std::string op_read = "open (read the schema version)";
  std::int64_t version = PragmaInt(db, path, kReadVersion, op_read);
  CheckSchemaVersion(db, path, version);
  if (version == Store::kSchemaVersion) return;

  Transaction tx(db, path, "migrate the schema");
  // Another connection may have migrated between the read above and the lock.
  version = PragmaInt(db, path, kReadVersion, op_read);
  CheckSchemaVersion(db, path, version);
  if (version == Store::kSchemaVersion) return;
  if (version == 0 &&
      PragmaInt(db, path, "SELECT count(*) FROM sqlite_schema", "open (list the tables)") != 0)
    throw StoreError(
        Message(path, "open", "not an EOL test store (it has tables but no schema version)"));
  for (std::int64_t v = version; v < Store::kSchemaVersion; ++v)
    kMigrations[static_cast<std::size_t>(v)](db, path);
  // PRAGMA values cannot be bound; both are compile-time constants.
  const std::string set_ids = "PRAGMA application_id = " + std::to_string(schema::kApplicationId) +
                              "; PRAGMA user_version = " + std::to_string(Store::kSchemaVersion);
  Exec(db, path, set_ids.c_str(), "migrate the schema (set the version)");
  tx.Commit();
}

int AbortUnfinished(sqlite3* db, const std::string& path) {
  // The recovered records go to the outbox with them, in one transaction.
  Transaction tx(db, path, "open (mark unfinished tests ABORTED)");
  const std::string now = UtcNowIso8601();
  {
    Statement o(db, path,
                "INSERT INTO outbox (test_id, created_at) "
                "SELECT id, ?1 FROM tests WHERE outcome = 'RUNNING' ORDER BY id",
                "open (queue the aborted tests in the outbox)");
    o.BindText(1, now);
    o.Run();
  }
  Statement s(db, path,
              "UPDATE tests SET outcome = 'ABORTED', finished_at = ?1, reasons = ?2 "
              "WHERE outcome = 'RUNNING'",
              "open (mark unfinished tests ABORTED)");
  s.BindText(1, now);
  s.BindText(2, nlohmann::json::array(
                    {analysis::Reason{analysis::ReasonCode::kAborted, kInterruptedReason}})
                    .dump());
  s.Run();
  const int changed = sqlite3_changes(db);
  tx.Commit();
  return changed;
}

// ---- Writing -----------------------------------------------------------------------------

// Invalid UTF-8 in a string (a garbled barcode, a device's reply) must not lose the record.
std::string Dump(const nlohmann::json& j) {
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

void InsertTestRow(sqlite3* db, const std::string& path, TestRecord& record) {
  const std::string op = "begin the test of serial '" + record.serial + "'";
  if (record.serial.empty()) throw StoreError(Message(path, op, "record.serial is empty"));
  if (record.started_at.empty()) throw StoreError(Message(path, op, "record.started_at is empty"));
  Statement s(db, path, R"sql(
    INSERT INTO tests (serial, station_id, recipe_id, recipe_version, recipe_hash,
                       software_version, started_at, outcome, retest_of, kind,
                       operator_id, shift, order_number)
    VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, 'RUNNING',
            (SELECT min(id) FROM tests WHERE serial = ?1), ?8, ?9, ?10, ?11)
    RETURNING id, retest_of)sql",
              op);
  s.BindText(1, record.serial);
  s.BindText(2, record.station_id);
  s.BindText(3, record.recipe_id);
  s.BindInt(4, record.recipe_version);
  s.BindText(5, record.recipe_hash);
  s.BindText(6, record.software_version);
  s.BindText(7, record.started_at);
  s.BindText(8, ToString(record.kind));
  s.BindText(9, record.work.operator_id);
  s.BindText(10, record.work.shift);
  s.BindText(11, record.work.order_number);
  if (!s.Step()) throw StoreError(Message(path, op, "the insert returned no id"));
  const std::int64_t id = s.Int(0);
  const std::optional<std::int64_t> retest_of = s.OptInt(1);
  s.Run();  // completes the statement (and, outside a transaction, commits it)
  record.id = id;
  record.retest_of = retest_of;
}

// The caller holds the transaction.
void WriteFinish(sqlite3* db, const std::string& path, const TestRecord& record) {
  const std::string op = "finish test " + std::to_string(record.id);
  if (record.finished_at.empty())
    throw StoreError(Message(path, op, "record.finished_at is empty"));
  nlohmann::json j = record;
  j.erase("curves");  // stored compressed, one row each
  {
    Statement s(db, path,
                "UPDATE tests SET outcome = ?2, finished_at = ?3, reasons = ?4, record = ?5 "
                "WHERE id = ?1 AND outcome = 'RUNNING'",
                op);
    s.BindInt(1, record.id);
    s.BindText(2, analysis::ToString(record.outcome));
    s.BindText(3, record.finished_at);
    s.BindText(4, Dump(nlohmann::json(record.reasons)));
    s.BindText(5, Dump(j));
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

// ---- Reading -----------------------------------------------------------------------------

constexpr std::string_view kSelectTests =
    "SELECT id, serial, station_id, recipe_id, recipe_version, recipe_hash, software_version, "
    "started_at, finished_at, outcome, retest_of, reasons, record, kind, operator_id, shift, "
    "order_number FROM tests ";

TestRecord RowToRecord(const Statement& s, const std::string& path) {
  const std::int64_t id = s.Int(0);
  const std::string op = "read test " + std::to_string(id);
  TestRecord r;
  try {
    // An aborted test has no record JSON: its columns are all there is.
    if (!s.IsNull(12)) r = nlohmann::json::parse(s.Text(12)).get<TestRecord>();
    r.reasons = nlohmann::json::parse(s.Text(11)).get<std::vector<analysis::Reason>>();
  } catch (const nlohmann::json::exception& e) {
    throw StoreError(Message(path, op, std::string("stored JSON is not a record: ") + e.what()));
  } catch (const std::invalid_argument& e) {  // an unknown enum string (test_record.h)
    throw StoreError(Message(path, op, std::string("stored record: ") + e.what()));
  }
  r.id = id;
  r.serial = s.Text(1);
  r.station_id = s.Text(2);
  r.recipe_id = s.Text(3);
  r.recipe_version = static_cast<int>(s.Int(4));
  r.recipe_hash = s.Text(5);
  r.software_version = s.Text(6);
  r.started_at = s.Text(7);
  r.finished_at = s.Text(8);
  const std::string outcome = s.Text(9);
  const std::optional<analysis::Outcome> parsed = analysis::ParseOutcome(outcome);
  if (!parsed) throw StoreError(Message(path, op, "unknown outcome '" + outcome + "'"));
  r.outcome = *parsed;
  r.retest_of = s.OptInt(10);
  try {
    r.kind = ParseRecordKind(s.Text(13));
  } catch (const std::invalid_argument& e) {
    throw StoreError(Message(path, op, e.what()));
  }
  r.work.operator_id = s.Text(14);
  r.work.shift = s.Text(15);
  r.work.order_number = s.Text(16);
  r.curves.clear();
  return r;
}

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

// Steps `s` (a kSelectTests query with its parameters bound) to the end.
std::vector<TestRecord> ReadTests(sqlite3* db, const std::string& path, Statement& s,
                                  bool with_curves) {
  std::vector<TestRecord> out;
  while (s.Step()) out.push_back(RowToRecord(s, path));
  if (with_curves && !out.empty()) {
    Statement c(db, path,
                "SELECT name, raw_size, data, encoding FROM curves WHERE test_id = ?1 ORDER BY id",
                "read curves");
    for (TestRecord& r : out) LoadCurves(c, path, r);
  }
  return out;
}

}  // namespace

namespace {

// The URI a kReadOnly store opens. A WAL database opened read-only makes SQLite create
// "-wal" and "-shm" beside it and leave them; while a writer has the file open they exist
// already and "mode=ro" shares them. Without a "-wal" no connection has it open (the last one
// to close removes it), so the file is opened "immutable": no lock and no file is created. A
// station that starts writing during such a read may make that read fail; it cannot make it
// write.
std::string ReadOnlyUri(const std::string& path) {
  std::string uri = "file:";
  for (const char ch : path) {
    if (ch == '%' || ch == '?' || ch == '#') {
      char esc[4];
      std::snprintf(esc, sizeof esc, "%%%02X", static_cast<unsigned char>(ch));
      uri += esc;
    } else {
      uri += ch;
    }
  }
  std::error_code ec;
  const bool writer_open = std::filesystem::exists(path + "-wal", ec);
  return uri + (writer_open ? "?mode=ro" : "?immutable=1");
}

}  // namespace

Store::Store(std::string path) : path_(std::move(path)) {}

Store::~Store() {
  sqlite3_close_v2(db_);
  if (lock_fd_ >= 0) ::close(lock_fd_);
}

std::unique_ptr<Store> Store::Open(const std::string& path, Role role) {
  std::unique_ptr<Store> store(new Store(path));
  if (role == Role::kReadOnly) {
    // sqlite3_open_v2 would name a missing file "unable to open database file".
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
      throw StoreError(Message(path, "open read-only", "no such file"));
  }
  if (role == Role::kWriter && path != ":memory:" && !path.empty()) {
    const std::string lock_path = path + ".lock";
    store->lock_fd_ = ::open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0600);
    if (store->lock_fd_ < 0)
      throw StoreError(
          Message(path, "lock", "cannot open " + lock_path + ": " + std::strerror(errno)));
    if (::flock(store->lock_fd_, LOCK_EX | LOCK_NB) != 0)
      throw StoreError(Message(path, "lock",
                               errno == EWOULDBLOCK
                                   ? "another station holds " + lock_path +
                                         " (one station per database; stop the other first)"
                                   : "cannot lock " + lock_path + ": " + std::strerror(errno)));
  }
  const int rc = role == Role::kReadOnly
                     ? sqlite3_open_v2(ReadOnlyUri(path).c_str(), &store->db_,
                                       SQLITE_OPEN_READONLY | SQLITE_OPEN_URI, nullptr)
                     : sqlite3_open_v2(path.c_str(), &store->db_,
                                       SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr);
  if (rc != SQLITE_OK) {
    const std::string detail =
        store->db_ != nullptr ? sqlite3_errmsg(store->db_) : sqlite3_errstr(rc);
    throw StoreError(Message(path, "open", detail + " (sqlite code " + std::to_string(rc) + ")"));
  }
  if (role == Role::kReadOnly) {
    sqlite3_extended_result_codes(store->db_, 1);
    sqlite3_busy_timeout(store->db_, kBusyTimeoutMs);
    const std::string op = "open read-only (read the schema version)";
    const std::int64_t version = PragmaInt(store->db_, path, "PRAGMA user_version", op);
    CheckSchemaVersion(store->db_, path, version);
    if (version != kSchemaVersion)
      throw StoreError(Message(path, "open read-only",
                               version == 0
                                   ? std::string("not an EOL test store (no schema)")
                                   : "schema version " + std::to_string(version) +
                                         ", this software reads " + std::to_string(kSchemaVersion) +
                                         "; let `eol station` migrate it first"));
    return store;
  }
  // SQLite falls back to read-only when the file is write-protected; the station must write.
  if (sqlite3_db_readonly(store->db_, "main") == 1)
    throw StoreError(Message(path, "open", "the file is read-only"));
  Configure(store->db_, path);
  Migrate(store->db_, path);
  if (role == Role::kWriter) store->aborted_on_open_ = AbortUnfinished(store->db_, path);
  return store;
}

void Store::BeginTest(TestRecord& record) { InsertTestRow(db_, path_, record); }

void Store::FinishTest(const TestRecord& record) {
  Transaction tx(db_, path_, "finish test " + std::to_string(record.id));
  WriteFinish(db_, path_, record);
  tx.Commit();
}

void Store::Insert(TestRecord& record) {
  // One transaction: an import is either fully there or not at all (never left RUNNING).
  Transaction tx(db_, path_, "insert the test of serial '" + record.serial + "'");
  const std::int64_t id = record.id;
  const std::optional<std::int64_t> retest_of = record.retest_of;
  try {
    InsertTestRow(db_, path_, record);
    WriteFinish(db_, path_, record);
    tx.Commit();
  } catch (...) {
    // Rolled back: the record must not carry an id that is not in the file.
    record.id = id;
    record.retest_of = retest_of;
    throw;
  }
}

void Store::InsertAll(std::vector<TestRecord>& records) {
  Transaction tx(db_, path_, "insert " + std::to_string(records.size()) + " tests");
  std::vector<std::pair<std::int64_t, std::optional<std::int64_t>>> before;
  before.reserve(records.size());
  for (const TestRecord& r : records) before.emplace_back(r.id, r.retest_of);
  try {
    for (TestRecord& r : records) {
      InsertTestRow(db_, path_, r);
      WriteFinish(db_, path_, r);
    }
    tx.Commit();
  } catch (...) {
    for (std::size_t i = 0; i < records.size(); ++i)
      std::tie(records[i].id, records[i].retest_of) = before[i];
    throw;
  }
}

std::vector<TestRecord> Store::TestsOfSerial(const std::string& serial, bool with_curves) {
  Statement s(db_, path_,
              std::string(kSelectTests) +
                  "WHERE serial = ?1 AND outcome <> 'RUNNING' ORDER BY started_at DESC, id DESC",
              "tests of serial '" + serial + "'");
  s.BindText(1, serial);
  return ReadTests(db_, path_, s, with_curves);
}

std::optional<TestRecord> Store::LatestOfSerial(const std::string& serial) {
  Statement s(db_, path_,
              std::string(kSelectTests) +
                  "WHERE serial = ?1 AND outcome <> 'RUNNING' "
                  "ORDER BY started_at DESC, id DESC LIMIT 1",
              "latest test of serial '" + serial + "'");
  s.BindText(1, serial);
  std::vector<TestRecord> found = ReadTests(db_, path_, s, /*with_curves=*/true);
  if (found.empty()) return std::nullopt;
  return std::move(found.front());
}

std::optional<TestRecord> Store::Test(std::int64_t id, bool with_curves) {
  Statement s(db_, path_, std::string(kSelectTests) + "WHERE id = ?1 AND outcome <> 'RUNNING'",
              "read test " + std::to_string(id));
  s.BindInt(1, id);
  std::vector<TestRecord> found = ReadTests(db_, path_, s, with_curves);
  if (found.empty()) return std::nullopt;
  return std::move(found.front());
}

std::vector<TestRecord> Store::Tests(const TestQuery& query) {
  // Only fixed clauses are appended; every value is a bound parameter.
  std::string sql = std::string(kSelectTests) + "WHERE outcome <> 'RUNNING'";
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
  s.Step();
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

std::vector<MeasurementRow> Store::MeasurementRows(const MeasurementQuery& q) {
  // Only fixed clauses are appended; every value is a bound parameter.
  std::string sql =
      "SELECT t.id, t.serial, t.started_at, t.outcome, t.recipe_id, t.recipe_version, "
      "t.recipe_hash, m.name, m.unit, m.value, m.lo, m.hi FROM measurements m "
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
  while (s.Step()) {
    MeasurementRow r;
    r.test_id = s.Int(0);
    r.serial = s.Text(1);
    r.started_at = s.Text(2);
    const std::optional<analysis::Outcome> o = analysis::ParseOutcome(s.Text(3));
    if (!o) throw StoreError(Message(path_, "read measurements", "unknown outcome " + s.Text(3)));
    r.outcome = *o;
    r.recipe_id = s.Text(4);
    r.recipe_version = static_cast<int>(s.Int(5));
    r.recipe_hash = s.Text(6);
    r.name = s.Text(7);
    r.unit = s.Text(8);
    r.value = s.OptReal(9);
    r.lo = s.OptReal(10);
    r.hi = s.OptReal(11);
    out.push_back(std::move(r));
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
