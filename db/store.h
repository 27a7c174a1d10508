// Durable store of test records in one SQLite file.
//
// Contract (the station relies on every line):
// - Open() creates or migrates the schema (versioned with PRAGMA user_version), turns on WAL
//   and synchronous=FULL, and marks every test left unfinished by a crash as ABORTED.
// - Open() refuses a file it must not use, with StoreRefused naming the file and the cause,
//   before it writes anything (and, for a file that is not a store, before any side file):
//   a file that is not an SQLite database; an existing file that is empty (0 bytes) or a
//   database without the store's schema, unless OpenOptions::create_if_empty; a store that
//   PRAGMA quick_check finds damaged (kWriter and kReadOnly; the first problems it names,
//   e.g. "Tree 4 page 12: ..."). A new store is created only where no file exists.
// - BeginTest() writes a row for a test that has started; until FinishTest() it is RUNNING,
//   which no query ever reports as PASS (queries skip running rows; after a crash they are
//   ABORTED).
// - FinishTest() writes the whole record in one transaction and returns only once it is
//   committed durably and (kWriter) copied from the WAL into the database file (a TRUNCATE
//   checkpoint) and noted in "<path>.last-verdict": the verdict may be published after it
//   returns, never before. A deleted or damaged WAL then loses no acknowledged verdict, and a
//   store that lost one anyway (an older copy restored, a checkpoint readers held off) is
//   named at the next Open() (loss_on_open()).
// - A FinishTest() that fails (a full disk, a bad record) leaves no RUNNING row behind: the
//   test is finished as ERROR "store write failed: <cause>" at once, or, when even that
//   cannot be written, before the next write, which fails while it cannot
//   (write_failure() says why until a write succeeds).
// - Retests: a test of a serial that already has tests links to the first one (retest_of).
// - Outbox (schema v5): every finished record, and every test recovered as ABORTED, gets an
//   outbox row in the same transaction; publishers read the rows after their own cursor, in
//   order, and advance it only once delivered: an outage of any length loses nothing.
// - Teardown findings (schema v7): append-only (the schema's triggers refuse UPDATE and
//   DELETE); a correction is a new entry that names the one it corrects, so the history of a
//   serial is every entry ever recorded, each with the engineer's name and time; the newest
//   entry of a serial is its current finding. An entry is accepted only for a serial with a
//   finished test in this store, and records which test (the newest) it judges.
// - All SQL is parameterised. Errors throw StoreError naming the file and the operation.
// Not thread-safe: one Store per thread (SQLite connections are cheap).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "db/test_record.h"

struct sqlite3;

namespace eol::db {

class StoreError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The file is not a store this software may use as it is: damaged (SQLite reports corruption,
// quick_check finds a problem), not an SQLite database, emptied, or without the store's schema.
// Restarting does not help: a person must restore, move or initialise the file.
class StoreRefused : public StoreError {
 public:
  using StoreError::StoreError;
};

// How Open() treats the file.
struct OpenOptions {
  // Make an existing empty file (0 bytes, or an SQLite database without tables and without
  // the store's ids) a new store, and a missing file a new one even where
  // "<path>.last-verdict" says a store with verdicts was there (`eol station --init-store`).
  // Without it such a file is refused: a store truncated or replaced by accident must not
  // start again from nothing without a word.
  bool create_if_empty = false;
  // kWriter: copy each finished test from the WAL into the database file (TRUNCATE
  // checkpoint). Off only to measure what it costs (`eol db-bench`).
  bool checkpoint_each_test = true;
  // kWriter, kReader: a cap on the file's size in pages (PRAGMA max_page_count; never below
  // the current size); 0: SQLite's. Past it a write fails as on a full disk ("database or
  // disk is full"), which is how the tests fill the disk.
  std::int64_t max_page_count = 0;
  // How long PRAGMA quick_check may take at open (its time grows with the file); past it the
  // check is interrupted, the store is used, and check_on_open() says the check was cut
  // short. -1: kWriterCheckBudgetMs for kWriter (under systemd's 90 s start timeout),
  // kReadOnlyCheckBudgetMs for kReadOnly (each `eol query` pays it on a large store).
  int quick_check_budget_ms = -1;
};

inline constexpr int kWriterCheckBudgetMs = 20000;
inline constexpr int kReadOnlyCheckBudgetMs = 2000;

struct TestQuery {
  std::optional<std::string> from;  // ISO 8601, inclusive, on started_at
  std::optional<std::string> to;    // ISO 8601, exclusive
  std::optional<analysis::Outcome> outcome;
  std::optional<std::string> serial;
  std::optional<std::string> order_number;  // schema v4
  // Keyset paging in the result's order (started_at DESC, id DESC): only tests after this
  // (started_at, id) in that order; give the last test of the previous page.
  std::optional<std::pair<std::string, std::int64_t>> after;
  int limit = 100;
  bool with_curves = false;
};

// One change of a recipe through the API: who (token name), with which role, when, and the
// recipe's version and SHA-256 before and after.
struct RecipeAudit {
  std::string at;  // ISO 8601 UTC
  std::string who;
  std::string role;
  std::string recipe_id;
  std::optional<int> old_version;
  int new_version = 0;
  std::string old_hash;  // empty for a new recipe
  std::string new_hash;
  std::string path;  // the file written
};

// One master test of a self-check (schema v3), as the store keeps it.
struct SelfCheckEntry {
  std::int64_t test_id = 0;
  std::string at;  // ISO 8601 UTC, when the master's test finished
  std::string station_id;
  std::string master;  // "good" or "limit"
  std::string serial;
  bool passed = false;
  std::string detail;
};

// What teardown of a unit found (schema v7).
enum class TeardownFinding { kDefective, kNotDefective };
// "defective", "not-defective" (the CLI's and the API's words; the table stores
// 'defective' and 'not_defective').
const char* ToString(TeardownFinding f);
// Accepts "defective", "not-defective" and "not_defective"; empty for anything else.
std::optional<TeardownFinding> ParseTeardownFinding(std::string_view text);

// One finding an engineer recorded for a serial.
struct TeardownEntry {
  std::int64_t id = 0;  // set by AppendTeardown
  std::string serial;
  TeardownFinding found = TeardownFinding::kDefective;
  std::string note;
  std::string by;  // the engineer's name (token name through the API), never empty
  std::string at;  // ISO 8601 UTC, when it was recorded
  // Set by AppendTeardown: the serial's newest finished test then (the verdict judged) and
  // the serial's previous newest entry, which this one corrects (empty for the first).
  std::optional<std::int64_t> test_id;
  std::optional<std::int64_t> corrects;
};

// Measurement rows of finished tests for statistics, oldest first.
struct MeasurementQuery {
  std::optional<std::string> from;  // ISO 8601, inclusive, on started_at
  std::optional<std::string> to;    // exclusive
  std::optional<std::string> recipe_hash;
  std::optional<std::string> serial;
  RecordKind kind = RecordKind::kProduction;
};

struct MeasurementRow {
  std::int64_t test_id = 0;
  std::string serial;
  std::string started_at;
  analysis::Outcome outcome = analysis::Outcome::kError;
  std::string recipe_id;
  int recipe_version = 0;
  std::string recipe_hash;
  std::string name;
  std::string unit;
  std::optional<double> value;  // empty where the stored value was not finite
  std::optional<double> lo;
  std::optional<double> hi;
};

// What yield counts of each finished (or aborted) test (station/reports/yield.h), without the
// record JSON: identity, outcome, reasons, the first test's link and the recipe.
struct OutcomeQuery {
  std::optional<std::string> from;  // ISO 8601, inclusive, on started_at
  std::optional<std::string> to;    // exclusive
  std::optional<std::string> recipe_hash;
  RecordKind kind = RecordKind::kProduction;
};

struct OutcomeRow {
  std::int64_t test_id = 0;
  std::string serial;
  std::string started_at;
  analysis::Outcome outcome = analysis::Outcome::kError;
  // Empty for the serial's first stored test (of any kind, in or before the window).
  std::optional<std::int64_t> retest_of;
  std::string recipe_id;
  int recipe_version = 0;
  std::string recipe_hash;
  std::vector<analysis::Reason> reasons;  // the decisive first
};

// One row of the outbox: the record of test `test_id`, to be delivered in `id` order.
struct OutboxEntry {
  std::int64_t id = 0;
  std::int64_t test_id = 0;
  std::string created_at;  // ISO 8601 UTC, when the record was stored
};

class Store {
 public:
  static constexpr int kSchemaVersion = 7;

  // kWriter: the station's one connection; recovers unfinished tests as ABORTED. It holds an
  // exclusive flock on "<path>.lock" (created 0600 beside the file) for as long as it is open:
  // a second writer, e.g. a second `eol station` on the same database, gets a StoreError
  // before it can recover (abort) the first one's running test.
  // kReader: further connections (the HTTP API, queries, exports) that must never touch a
  // test another connection is running; they migrate a new file but recover nothing.
  // kReadOnly: a reader that never writes (queries, exports, stats): it opens an existing
  // store read-only, so it works on a file it may not write (a copy, a read-only share) and
  // never creates or migrates one; a missing file or another schema version is a StoreError.
  // PRAGMA quick_check runs for kWriter (on an existing file) and kReadOnly, not for kReader
  // (the station's further connections, opened after its writer checked the file). Its cost
  // grows with the file: `eol db-bench` measures it (open_read_only_s, open_writer_s).
  // kWriter also keeps "<path>.last-verdict" (db/last_verdict.h) beside the file.
  enum class Role { kWriter, kReader, kReadOnly };

  static std::unique_ptr<Store> Open(const std::string& path, Role role = Role::kWriter,
                                     const OpenOptions& options = {});
  ~Store();
  Store(const Store&) = delete;
  Store& operator=(const Store&) = delete;

  const std::string& path() const { return path_; }
  // How many unfinished tests Open() found and marked ABORTED.
  int aborted_on_open() const { return aborted_on_open_; }
  // kWriter: verdicts acknowledged earlier that Open() found missing from the store, named
  // ("the store ends at test 41, but test 44 (PASS, serial M-7) was acknowledged at ...");
  // empty when none. Found from "<path>.last-verdict" (the newest acknowledged test and its
  // outcome) and the outbox cursors (a publisher that delivered rows the outbox no longer
  // has). New tests then get ids above every acknowledged one, so no id is used twice.
  const std::string& loss_on_open() const { return loss_on_open_; }
  // "" when Open() checked the whole file (or created it); otherwise that PRAGMA quick_check
  // ran out of its budget (OpenOptions::quick_check_budget_ms) before the file's end.
  const std::string& check_on_open() const { return check_on_open_; }
  // The last write that failed (e.g. "... database or disk is full"), until a write
  // succeeds; empty while writes work. The station shows it as the reason it is not ready.
  const std::string& write_failure() const { return write_failure_; }

  // Sets record.id and record.retest_of; writes serial, station, recipe, times.
  void BeginTest(TestRecord& record);
  // record.id must come from BeginTest. Durable when it returns (see the contract above).
  void FinishTest(const TestRecord& record);
  // BeginTest + FinishTest, for records made elsewhere (imports, tests).
  void Insert(TestRecord& record);
  // Insert for many records in one transaction (bulk imports, generated benchmark stores):
  // all are there or none; each record's id and retest_of are set.
  void InsertAll(std::vector<TestRecord>& records);

  // Finished (and aborted) tests of a serial, newest first.
  std::vector<TestRecord> TestsOfSerial(const std::string& serial, bool with_curves = false);
  // The newest finished (or aborted) test of a serial, with its curves.
  std::optional<TestRecord> LatestOfSerial(const std::string& serial);
  // Empty for an unknown id and for a test still RUNNING.
  std::optional<TestRecord> Test(std::int64_t id, bool with_curves = true);
  // Newest first; limit is clamped to 1..10000. from/to compare as strings, which is time
  // order for the store's one timestamp format (db/clock.h); a date "2024-05-01" also works.
  std::vector<TestRecord> Tests(const TestQuery& query);

  void AppendAudit(const RecipeAudit& entry);
  std::vector<RecipeAudit> AuditLog(int limit = 100);  // newest first

  // Self-checks, newest first (written by FinishTest for records of kind "self_check").
  std::vector<SelfCheckEntry> SelfChecks(int limit = 100);
  // The newest check of one master ("good" or "limit"), if any.
  std::optional<SelfCheckEntry> LatestSelfCheck(const std::string& master);
  // Finished (or aborted) tests of `kind` that started at or after `since` (ISO 8601).
  int CountTestsSince(RecordKind kind, const std::string& since);
  // Every measurement row of finished PASS/FAIL/ERROR tests matching the query, in test order
  // (started_at, id), at most 1,000,000 rows.
  std::vector<MeasurementRow> MeasurementRows(const MeasurementQuery& query);
  // Every finished or aborted test matching the query, in test order (started_at, id), at
  // most 1,000,000 rows.
  std::vector<OutcomeRow> OutcomeRows(const OutcomeQuery& query);

  // Records a teardown finding (`entry.id`, `test_id` and `corrects` are set here and in the
  // returned copy) in one transaction. Throws std::invalid_argument naming the cause, before
  // writing, for an empty serial, name or time, and for a serial without a finished test in
  // this store; StoreError when the write fails.
  TeardownEntry AppendTeardown(const TeardownEntry& entry);
  // Every finding recorded for `serial`, oldest first (the last one is current).
  std::vector<TeardownEntry> TeardownsOfSerial(const std::string& serial);
  // The current finding of every serial that has one, by serial.
  std::vector<TeardownEntry> CurrentTeardowns();

  // The outbox rows after `consumer`'s cursor, oldest first, at most `limit` (1..10000).
  std::vector<OutboxEntry> OutboxAfterCursor(const std::string& consumer, int limit);
  // Moves `consumer`'s cursor to `id` (the row just delivered); a cursor never moves back.
  void AdvanceOutboxCursor(const std::string& consumer, std::int64_t id);
  // The id of the newest row `consumer` has delivered (0: none).
  std::int64_t OutboxCursor(const std::string& consumer);
  // Rows after `consumer`'s cursor.
  std::int64_t OutboxPending(const std::string& consumer);

  // SQLite's own consistency check: "ok" or the first problem it finds.
  std::string IntegrityCheck();
  // Rows still RUNNING (a test in flight, or left by a crash not yet recovered).
  int CountRunning();

 private:
  explicit Store(std::string path);
  void OpenWriterFiles(const OpenOptions& options);
  // Finishes as ERROR the tests whose FinishTest failed (failed_finishes_); throws while it
  // cannot. Every write calls it first.
  void FinishFailedWrites();
  void AfterVerdict(const TestRecord& record);
  void Failed(const StoreError& e);

  std::string path_;
  sqlite3* db_ = nullptr;
  int aborted_on_open_ = 0;
  int lock_fd_ = -1;     // kWriter: "<path>.lock", flock'ed exclusively while the store is open
  int verdict_fd_ = -1;  // kWriter: "<path>.last-verdict" (db/last_verdict.h)
  bool checkpoint_each_test_ = false;
  std::int64_t id_floor_ = 0;  // new tests get ids >= this (above every acknowledged one)
  std::string loss_on_open_;
  std::string check_on_open_;
  std::string write_failure_;
  // Tests whose FinishTest failed and that are still RUNNING: id and the failure.
  std::vector<std::pair<std::int64_t, std::string>> failed_finishes_;
};

}  // namespace eol::db
