// Issue 34: a store that refuses damage (db/store.h). Real SQLite files in a temporary
// directory, damaged the way a disk, a person or a crash damages them: a zeroed page, a file
// truncated to 0 bytes, a file that is no store, a WAL lost or torn after the verdicts were
// acknowledged, a disk that fills during a test.
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "db/last_verdict.h"
#include "db/store.h"

namespace eol::db {
namespace {

namespace fs = std::filesystem;
using analysis::Outcome;

// Runs `statement`, which must throw StoreRefused whose message contains every one of `parts`.
#define EXPECT_REFUSED(statement, ...)                                                \
  do {                                                                                \
    try {                                                                             \
      statement;                                                                      \
      ADD_FAILURE() << #statement " did not throw";                                   \
    } catch (const StoreRefused& e) {                                                 \
      for (const std::string& part : std::initializer_list<std::string>{__VA_ARGS__}) \
        EXPECT_NE(std::string(e.what()).find(part), std::string::npos)                \
            << "message: " << e.what() << "\nlacks: " << part;                        \
    }                                                                                 \
  } while (false)

// Raw SQLite access behind the store's back.
class RawDb {
 public:
  explicit RawDb(const fs::path& path) { EXPECT_EQ(sqlite3_open(path.c_str(), &db_), SQLITE_OK); }
  ~RawDb() { sqlite3_close(db_); }
  RawDb(const RawDb&) = delete;
  RawDb& operator=(const RawDb&) = delete;
  void Exec(const std::string& sql) {
    char* err = nullptr;
    EXPECT_EQ(sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &err), SQLITE_OK)
        << sql << ": " << (err != nullptr ? err : "");
    sqlite3_free(err);
  }
  std::string One(const std::string& sql) {
    sqlite3_stmt* s = nullptr;
    EXPECT_EQ(sqlite3_prepare_v2(db_, sql.c_str(), -1, &s, nullptr), SQLITE_OK) << sql;
    std::string out = "(no row)";
    if (sqlite3_step(s) == SQLITE_ROW) {
      const auto* t = reinterpret_cast<const char*>(sqlite3_column_text(s, 0));
      out = t != nullptr ? t : "NULL";
    }
    sqlite3_finalize(s);
    return out;
  }

 private:
  sqlite3* db_ = nullptr;
};

TestRecord Record(const std::string& serial, int curve_points = 0) {
  TestRecord r;
  r.serial = serial;
  r.station_id = "EOL-9";
  r.recipe_id = "pm-motor-a";
  r.recipe_version = 3;
  r.recipe_hash = std::string(64, 'b');
  r.software_version = "test";
  r.started_at = "2026-11-28T10:00:00.000Z";
  r.finished_at = "2026-11-28T10:00:01.000Z";
  r.outcome = Outcome::kPass;
  if (curve_points > 0) {
    Curve c;
    c.name = "impedance";
    for (int k = 0; k < curve_points; ++k) {
      c.freq_hz.push_back(10.0 + k);
      c.re.push_back(1.0 + 1e-3 * k * k);  // nothing that compresses to nothing
      c.im.push_back(0.5 / (1.0 + k));
    }
    r.curves = {c};
  }
  return r;
}

// Begins and finishes one test as the station does; returns its id.
std::int64_t RunTest(Store& store, const std::string& serial, int curve_points = 0) {
  TestRecord r = Record(serial, curve_points);
  store.BeginTest(r);
  store.FinishTest(r);
  return r.id;
}

std::set<std::string> Files(const fs::path& dir) {
  std::set<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) out.insert(e.path().filename().string());
  return out;
}

std::string Bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class StoreGuardTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("eol_guard_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    path_ = dir_ / "eol.sqlite";
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string path() const { return path_.string(); }

  fs::path dir_;
  fs::path path_;
};

TEST_F(StoreGuardTest, AZeroedPageIsRefusedNamingThePageAndNothingIsWritten) {
  {
    auto store = Store::Open(path());
    for (int i = 0; i < 40; ++i) RunTest(*store, "Z-" + std::to_string(i), 200);
  }
  int page = 0, page_size = 0;
  {
    RawDb raw(path_);
    // The root page of the tests table: where the next PASS would be written.
    page = std::stoi(raw.One("SELECT rootpage FROM sqlite_schema WHERE name = 'tests'"));
    page_size = std::stoi(raw.One("PRAGMA page_size"));
  }
  ASSERT_GT(page, 1);
  {
    std::fstream f(path_, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(page - 1) * page_size);
    f.write(std::string(static_cast<std::size_t>(page_size), '\0').data(), page_size);
  }
  const std::string before = Bytes(path_);
  EXPECT_REFUSED(Store::Open(path()), path(), "quick_check", "damaged",
                 "Page " + std::to_string(page) + ": ");
  EXPECT_REFUSED(Store::Open(path(), Store::Role::kReadOnly), path(), "quick_check",
                 "Page " + std::to_string(page) + ": ");
  EXPECT_EQ(Bytes(path_), before) << "a refused store was written";
}

// The check is bounded: past its budget it is interrupted and says so, and the store is used.
// (The interrupt itself lands at the budget only as the scheduler allows; a budget of 0 skips
// the check, deterministically.)
TEST_F(StoreGuardTest, AQuickCheckPastItsBudgetIsCutShortAndSaysSo) {
  {
    auto store = Store::Open(path());
    for (int i = 0; i < 4; ++i) RunTest(*store, "B-" + std::to_string(i));
  }
  OpenOptions none;
  none.quick_check_budget_ms = 0;
  auto store = Store::Open(path(), Store::Role::kReadOnly, none);
  EXPECT_EQ(store->check_on_open(), "PRAGMA quick_check not run (its budget is 0 s)");
  EXPECT_EQ(store->Tests({}).size(), 4u);
  EXPECT_EQ(Store::Open(path(), Store::Role::kReadOnly)->check_on_open(), "");
  EXPECT_EQ(Store::Open(path())->check_on_open(), "");
}

TEST_F(StoreGuardTest, AStoreTruncatedToZeroBytesIsRefusedAndOnlyTheFlagMakesANewOne) {
  std::int64_t last = 0;
  {
    auto store = Store::Open(path());
    for (int i = 1; i <= 6; ++i) last = RunTest(*store, "T-" + std::to_string(i));
  }
  fs::resize_file(path_, 0);
  EXPECT_REFUSED(Store::Open(path()), path(), "empty (0 bytes)", "--init-store");
  EXPECT_REFUSED(Store::Open(path(), Store::Role::kReader), path(), "empty (0 bytes)");
  EXPECT_REFUSED(Store::Open(path(), Store::Role::kReadOnly), path(), "empty (0 bytes)");
  EXPECT_EQ(fs::file_size(path_), 0u) << "the refused file was made a store";

  OpenOptions init;
  init.create_if_empty = true;
  auto store = Store::Open(path(), Store::Role::kWriter, init);
  // The new store still says what the old one had acknowledged, and never reuses its ids.
  EXPECT_NE(store->loss_on_open().find("the store ends at test 0, but test " +
                                       std::to_string(last) + " (PASS, serial T-6)"),
            std::string::npos)
      << store->loss_on_open();
  EXPECT_NE(store->loss_on_open().find("tests 1 to 6 are lost"), std::string::npos)
      << store->loss_on_open();
  EXPECT_EQ(RunTest(*store, "T-7"), last + 1);
}

TEST_F(StoreGuardTest, ADeletedStoreIsNotSilentlyRecreatedWhileItsVerdictsAreKnown) {
  { RunTest(*Store::Open(path()), "D-1"); }
  fs::remove(path_);
  EXPECT_REFUSED(Store::Open(path()), path(), "no such file", "test 1 (PASS, serial D-1)",
                 "--init-store");
  EXPECT_FALSE(fs::exists(path_));
  OpenOptions init;
  init.create_if_empty = true;
  EXPECT_EQ(RunTest(*Store::Open(path(), Store::Role::kWriter, init), "D-2"), 2);
}

TEST_F(StoreGuardTest, AFileThatIsNoStoreIsRefusedBeforeAnySideFileIsCreated) {
  const fs::path passwd = dir_ / "passwd";
  std::ofstream(passwd) << "root:x:0:0:root:/root:/bin/bash\ndaemon:x:1:1::/usr/sbin:/bin/sh\n";
  const std::string before = Bytes(passwd);
  for (const Store::Role role :
       {Store::Role::kWriter, Store::Role::kReader, Store::Role::kReadOnly}) {
    EXPECT_REFUSED(Store::Open(passwd.string(), role), passwd.string(), "not a database",
                   "root:x:0:0", "nothing was created beside it");
  }
  OpenOptions init;
  init.create_if_empty = true;  // the flag is for empty files only
  EXPECT_REFUSED(Store::Open(passwd.string(), Store::Role::kWriter, init), "not a database");
  EXPECT_EQ(Files(dir_), std::set<std::string>{"passwd"});
  EXPECT_EQ(Bytes(passwd), before);

  // Another application's SQLite database: refused from its header, before any side file.
  const fs::path other = dir_ / "other.sqlite";
  {
    RawDb raw(other);
    raw.Exec("PRAGMA application_id = 1234; CREATE TABLE parts (id INTEGER)");
  }
  EXPECT_REFUSED(Store::Open(other.string()), "not an EOL test store", "application_id 1234");
  EXPECT_EQ(Files(dir_), (std::set<std::string>{"other.sqlite", "passwd"}));
}

TEST_F(StoreGuardTest, AnSqliteFileWithoutTheSchemaIsRefusedUnlessTheFlagSaysSo) {
  {
    RawDb raw(path_);
    raw.Exec("CREATE TABLE t (x); DROP TABLE t");  // a valid SQLite file, no tables
  }
  EXPECT_REFUSED(Store::Open(path()), "without the store's schema", "--init-store");
  RawDb raw(path_);
  EXPECT_EQ(raw.One("SELECT count(*) FROM sqlite_schema"), "0");
  EXPECT_EQ(raw.One("PRAGMA journal_mode"), "delete") << "the refused file was switched to WAL";
  OpenOptions init;
  init.create_if_empty = true;
  EXPECT_EQ(RunTest(*Store::Open(path(), Store::Role::kWriter, init), "E-1"), 1);
}

// Each verdict is checkpointed: the database file alone (its WAL deleted after a crash) holds
// every acknowledged verdict. The store is still open, as at a kill -9.
TEST_F(StoreGuardTest, EachVerdictIsInTheDatabaseFileNotOnlyInTheWal) {
  for (const bool checkpoint : {true, false}) {
    SCOPED_TRACE(checkpoint ? "checkpointed" : "not checkpointed");
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    { RunTest(*Store::Open(path()), "W-0"); }  // closing checkpoints: the schema is in the file
    OpenOptions options;
    options.checkpoint_each_test = checkpoint;
    auto store = Store::Open(path(), Store::Role::kWriter, options);
    for (int i = 1; i <= 3; ++i) RunTest(*store, "W-" + std::to_string(i));
    if (checkpoint) {
      EXPECT_EQ(fs::file_size(path().append("-wal")), 0u);
    }
    const fs::path copy_dir = dir_ / "copy";
    fs::create_directories(copy_dir);
    fs::copy_file(path_, copy_dir / "eol.sqlite");  // without its -wal
    fs::copy_file(LastVerdictPath(path()), LastVerdictPath((copy_dir / "eol.sqlite").string()));
    auto copy = Store::Open((copy_dir / "eol.sqlite").string());
    if (checkpoint) {
      EXPECT_EQ(copy->loss_on_open(), "");
      ASSERT_TRUE(copy->Test(4).has_value());
      EXPECT_EQ(copy->Test(4)->outcome, Outcome::kPass);
    } else {
      // The control: without the checkpoint the copy lost them, and says so.
      EXPECT_FALSE(copy->Test(4).has_value());
      EXPECT_EQ(copy->loss_on_open(),
                "the store ends at test 1, but test 4 (PASS, serial W-3) was acknowledged at "
                "2026-11-28T10:00:01.000Z: the records of tests 2 to 4 are lost (a deleted or "
                "damaged WAL, or an older copy of the file); new tests are numbered from 5");
      EXPECT_EQ(RunTest(*copy, "W-5"), 5) << "a lost test's id was used again";
    }
  }
}

// A WAL torn after the verdicts were acknowledged (the checkpoint held off by a reader of an
// older snapshot, then a crash): the verdict SQLite cannot replay is named at the next open.
TEST_F(StoreGuardTest, AVerdictLostWithATornWalIsNamedAtStart) {
  { RunTest(*Store::Open(path()), "R-0"); }
  sqlite3* snapshot = nullptr;
  ASSERT_EQ(sqlite3_open(path().c_str(), &snapshot), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(snapshot, "BEGIN; SELECT count(*) FROM tests", nullptr, nullptr, nullptr),
            SQLITE_OK);
  auto store = Store::Open(path());
  std::int64_t last = 0;
  for (int i = 1; i <= 3; ++i) last = RunTest(*store, "R-" + std::to_string(i), 300);
  const std::uintmax_t wal = fs::file_size(path().append("-wal"));
  ASSERT_GT(wal, 4096u) << "the reader did not hold the verdicts in the WAL";
  const fs::path copy = dir_ / "copy.sqlite";
  fs::copy_file(path_, copy);
  fs::copy_file(path().append("-wal"), copy.string() + "-wal");
  fs::resize_file(copy.string() + "-wal", wal - 3000);  // the last frames torn
  fs::copy_file(LastVerdictPath(path()), LastVerdictPath(copy.string()));
  sqlite3_exec(snapshot, "COMMIT", nullptr, nullptr, nullptr);
  sqlite3_close(snapshot);

  auto reopened = Store::Open(copy.string());
  const std::string loss = reopened->loss_on_open();
  EXPECT_NE(loss.find("test " + std::to_string(last) + " (PASS, serial R-3) was acknowledged"),
            std::string::npos)
      << loss;
  EXPECT_TRUE(loss.find("holds it as RUNNING") != std::string::npos ||
              loss.find("are lost") != std::string::npos)
      << loss;
}

TEST_F(StoreGuardTest, AnOutboxCursorPastTheOutboxIsNamed) {
  { RunTest(*Store::Open(path()), "O-1"); }
  {
    RawDb raw(path_);
    raw.Exec("INSERT INTO outbox_cursors (consumer, last_id) VALUES ('central', 9)");
  }
  EXPECT_EQ(Store::Open(path())->loss_on_open(),
            "the 'central' publisher delivered outbox row 9, but the outbox ends at row 1: "
            "records it delivered are not in the store");
}

// A full disk (PRAGMA max_page_count) in the middle of a test: the test ends ERROR naming the
// cause, nothing stays RUNNING, and the failure stands until a write succeeds.
TEST_F(StoreGuardTest, AFullDiskFinishesTheTestAsErrorAndLeavesNothingRunning) {
  { RunTest(*Store::Open(path()), "F-0"); }
  std::int64_t pages = 0;
  {
    RawDb raw(path_);
    pages = std::stoll(raw.One("PRAGMA page_count"));
  }
  OpenOptions full;
  full.max_page_count = pages + 2;
  auto store = Store::Open(path(), Store::Role::kWriter, full);
  TestRecord r = Record("F-1", 20000);  // curves of ~500 kB: far more than two pages
  store->BeginTest(r);
  EXPECT_THROW(store->FinishTest(r), StoreError);
  EXPECT_NE(store->write_failure().find("database or disk is full"), std::string::npos)
      << store->write_failure();
  EXPECT_EQ(store->CountRunning(), 0);
  const std::optional<TestRecord> stored = store->Test(r.id);
  ASSERT_TRUE(stored.has_value());
  EXPECT_EQ(stored->outcome, Outcome::kError);
  ASSERT_EQ(stored->reasons.size(), 1u);
  EXPECT_EQ(stored->reasons[0].code, analysis::ReasonCode::kStore);
  EXPECT_NE(stored->reasons[0].text.find("store write failed: "), std::string::npos);
  EXPECT_NE(stored->reasons[0].text.find("database or disk is full"), std::string::npos);
  EXPECT_EQ(store->OutboxAfterCursor("mqtt", 10).back().test_id, r.id) << "not published";
  // A small test still fits: the failure is over.
  RunTest(*store, "F-2");
  EXPECT_EQ(store->write_failure(), "");
}

// When even the ERROR cannot be written, the next write writes it first, and fails while it
// cannot. (Triggers stand in for the disk: they fail the writes deterministically.)
TEST_F(StoreGuardTest, ATestWhoseErrorCannotBeWrittenIsFinishedAtTheNextWrite) {
  { RunTest(*Store::Open(path()), "N-0"); }
  {
    RawDb raw(path_);
    raw.Exec(
        "CREATE TRIGGER full_verdict BEFORE UPDATE OF outcome ON tests "
        "BEGIN SELECT RAISE(ABORT, 'disk full (simulated)'); END");
  }
  auto store = Store::Open(path());
  TestRecord r = Record("N-1");
  store->BeginTest(r);
  EXPECT_THROW(store->FinishTest(r), StoreError);
  EXPECT_EQ(store->CountRunning(), 1) << "the trigger let the ERROR through";
  TestRecord next = Record("N-2");
  EXPECT_THROW(store->BeginTest(next), StoreError) << "a test began over a failed one";
  EXPECT_NE(store->write_failure().find("disk full (simulated)"), std::string::npos)
      << store->write_failure();
  {
    RawDb raw(path_);
    raw.Exec("DROP TRIGGER full_verdict");  // space again
  }
  store->BeginTest(next);               // finishes N-1 first
  EXPECT_EQ(store->CountRunning(), 1);  // N-2 only
  const std::optional<TestRecord> failed = store->Test(r.id);
  ASSERT_TRUE(failed.has_value());
  EXPECT_EQ(failed->outcome, Outcome::kError);
  EXPECT_NE(failed->reasons.at(0).text.find("store write failed: "), std::string::npos);
  EXPECT_NE(failed->reasons.at(0).text.find("disk full (simulated)"), std::string::npos);
  EXPECT_EQ(store->write_failure(), "");
}

TEST(LastVerdictFile, ATornSlotLeavesThePreviousVerdict) {
  const fs::path path = fs::temp_directory_path() / ("eol_lv_" + std::to_string(::getpid()));
  { std::ofstream(path).flush(); }
  std::FILE* f = std::fopen(path.c_str(), "r+");
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(WriteLastVerdict(fileno(f), {7, "PASS", "2026-11-28T10:00:00.000Z", "A 7"}), "");
  EXPECT_EQ(WriteLastVerdict(fileno(f), {8, "FAIL", "2026-11-28T10:01:00.000Z", "A\n8"}), "");
  std::fclose(f);
  std::string problem;
  std::optional<LastVerdict> v = ReadLastVerdict(path.string(), &problem);
  ASSERT_TRUE(v.has_value()) << problem;
  EXPECT_EQ(v->test_id, 8);
  EXPECT_EQ(v->outcome, "FAIL");
  EXPECT_EQ(v->serial, "A?8");
  // Test 8's slot (the first: even ids) torn: test 7 remains.
  {
    std::fstream io(path, std::ios::in | std::ios::out | std::ios::binary);
    io.seekp(40);
    io.write("XXXX", 4);
  }
  v = ReadLastVerdict(path.string(), &problem);
  ASSERT_TRUE(v.has_value()) << problem;
  EXPECT_EQ(v->test_id, 7);
  EXPECT_EQ(v->serial, "A 7");
  // Both torn: named, not mistaken for "nothing acknowledged".
  {
    std::fstream io(path, std::ios::in | std::ios::out | std::ios::binary);
    io.seekp(kLastVerdictSlotBytes + 40);
    io.write("XXXX", 4);
  }
  EXPECT_FALSE(ReadLastVerdict(path.string(), &problem).has_value());
  EXPECT_NE(problem.find("holds no valid entry"), std::string::npos) << problem;
  fs::remove(path);
}

}  // namespace
}  // namespace eol::db
