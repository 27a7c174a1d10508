#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "db/clock.h"
#include "db/last_verdict.h"
#include "db/schema.h"
#include "db/sqlite_statement.h"
#include "db/store.h"
#include "db/store_checks.h"

// Opening the store: the checks of the file (db/store_checks.h), the lock, the schema's
// migrations and the recovery of interrupted tests.
namespace eol::db {
namespace {

using internal::CheckFile;
using internal::Exec;
using internal::FileState;
using internal::FindLostDeliveries;
using internal::FindLostVerdict;
using internal::kBusyTimeoutMs;
using internal::Message;
using internal::PragmaInt;
using internal::QuickCheck;
using internal::Statement;
using internal::Transaction;

constexpr const char* kInterruptedReason = "interrupted: station stopped before the test finished";

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

void MigrateTo7(sqlite3* db, const std::string& path) {
  Exec(db, path, schema::kSchemaV7, "migrate the schema to version 7");
}

constexpr std::array<Migration, Store::kSchemaVersion> kMigrations = {
    &MigrateTo1, &MigrateTo2, &MigrateTo3, &MigrateTo4, &MigrateTo5, &MigrateTo6, &MigrateTo7};

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
    throw StoreRefused(Message(path, "open",
                               "not an EOL test store (application_id " + std::to_string(app_id) +
                                   ", user_version " + std::to_string(version) + ")"));
  if (version > Store::kSchemaVersion)
    throw StoreRefused(Message(path, "open",
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
    throw StoreRefused(
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

// Read before anything is written (a foreign database is not even switched to WAL): refuses a
// file of another application, of a newer schema, or with tables but no schema version; with
// `refuse_no_schema`, also an existing database without tables (an empty file that someone
// or something made an SQLite file). kReadOnly reads only the current schema.
void CheckIdentity(sqlite3* db, const std::string& path, Store::Role role, bool refuse_no_schema) {
  const std::string op = "open (read the schema version)";
  const std::int64_t version = PragmaInt(db, path, "PRAGMA user_version", op);
  CheckSchemaVersion(db, path, version);
  if (role == Store::Role::kReadOnly && version != Store::kSchemaVersion)
    throw StoreRefused(Message(
        path, "open read-only",
        version == 0
            ? std::string("not an EOL test store (no schema)")
            : "schema version " + std::to_string(version) + ", this software reads " +
                  std::to_string(Store::kSchemaVersion) + "; let `eol station` migrate it first"));
  if (version != 0) return;
  if (PragmaInt(db, path, "SELECT count(*) FROM sqlite_schema", "open (list the tables)") != 0)
    throw StoreRefused(
        Message(path, "open", "not an EOL test store (it has tables but no schema version)"));
  if (refuse_no_schema)
    throw StoreRefused(Message(
        path, "open",
        std::string("an SQLite database without the store's schema (no tables): not a store; ") +
            internal::kInitStoreHint));
}

// kWriter: the exclusive flock on "<path>.lock" (store.h).
int LockWriter(const std::string& path) {
  const std::string lock_path = path + ".lock";
  const int fd = ::open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0600);
  if (fd < 0)
    throw StoreError(
        Message(path, "lock", "cannot open " + lock_path + ": " + std::strerror(errno)));
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    ::close(fd);
    throw StoreError(Message(path, "lock",
                             err == EWOULDBLOCK
                                 ? "another station holds " + lock_path +
                                       " (one station per database; stop the other first)"
                                 : "cannot lock " + lock_path + ": " + std::strerror(err)));
  }
  return fd;
}

}  // namespace

Store::Store(std::string path) : path_(std::move(path)) {}

Store::~Store() {
  sqlite3_close_v2(db_);
  if (verdict_fd_ >= 0) ::close(verdict_fd_);
  if (lock_fd_ >= 0) ::close(lock_fd_);
}

std::unique_ptr<Store> Store::Open(const std::string& path, Role role, const OpenOptions& options) {
  std::unique_ptr<Store> store(new Store(path));
  const bool on_disk = path != ":memory:" && !path.empty();
  // Before anything is created beside it (the lock, SQLite's -wal and -shm).
  const FileState file = on_disk ? CheckFile(path, role, options) : FileState::kMissing;
  if (role == Role::kWriter && on_disk) store->lock_fd_ = LockWriter(path);
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
  sqlite3_extended_result_codes(store->db_, 1);
  sqlite3_busy_timeout(store->db_, kBusyTimeoutMs);
  CheckIdentity(store->db_, path, role, file == FileState::kHasBytes && !options.create_if_empty);
  if (role == Role::kReadOnly) {
    store->check_on_open_ =
        QuickCheck(store->db_, path,
                   options.quick_check_budget_ms >= 0 ? options.quick_check_budget_ms
                                                      : kReadOnlyCheckBudgetMs);
    return store;
  }
  // SQLite falls back to read-only when the file is write-protected; the station must write.
  if (sqlite3_db_readonly(store->db_, "main") == 1)
    throw StoreError(Message(path, "open", "the file is read-only"));
  Configure(store->db_, path);
  if (options.max_page_count > 0) {
    // PRAGMA values cannot be bound; this one is an integer.
    const std::string sql = "PRAGMA max_page_count = " + std::to_string(options.max_page_count);
    Exec(store->db_, path, sql.c_str(), "open (PRAGMA max_page_count)");
  }
  if (role == Role::kWriter && file != FileState::kMissing)
    store->check_on_open_ = QuickCheck(
        store->db_, path,
        options.quick_check_budget_ms >= 0 ? options.quick_check_budget_ms : kWriterCheckBudgetMs);
  Migrate(store->db_, path);
  if (role != Role::kWriter) return store;
  if (on_disk) store->OpenWriterFiles(options);
  store->aborted_on_open_ = AbortUnfinished(store->db_, path);
  return store;
}

// Opens "<path>.last-verdict" and compares what it says was acknowledged, and what the outbox
// cursors say was delivered, with the store (before AbortUnfinished, which would turn a
// RUNNING row of an acknowledged test into ABORTED).
void Store::OpenWriterFiles(const OpenOptions& options) {
  checkpoint_each_test_ = options.checkpoint_each_test;
  const std::string verdict_path = LastVerdictPath(path_);
  verdict_fd_ = ::open(verdict_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0600);
  if (verdict_fd_ < 0)
    throw StoreError(
        Message(path_, "open", "cannot open " + verdict_path + ": " + std::strerror(errno)));
  std::string problem;
  const std::optional<LastVerdict> acked = ReadLastVerdict(verdict_path, &problem);
  std::vector<std::string> found;
  if (!problem.empty()) found.push_back(problem);
  if (acked) {
    id_floor_ = acked->test_id + 1;
    if (std::string loss = FindLostVerdict(db_, path_, *acked); !loss.empty())
      found.push_back(std::move(loss));
  }
  for (std::string& loss : FindLostDeliveries(db_, path_)) found.push_back(std::move(loss));
  for (const std::string& f : found) loss_on_open_ += (loss_on_open_.empty() ? "" : "; ") + f;
}

}  // namespace eol::db
