// Schema version 7: teardown findings. Recorded per serial with who and when, append-only
// (corrections are new entries; the file itself refuses UPDATE and DELETE), refused for a
// serial the store never tested, and a version-6 file upgrades in place.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <stdexcept>
#include <string>

#include "../support/child_process.h"
#include "db/schema.h"
#include "db/store.h"

namespace eol::db {
namespace {

using analysis::Outcome;

TestRecord Record(const std::string& serial, const std::string& at, Outcome outcome) {
  TestRecord r;
  r.serial = serial;
  r.station_id = "S";
  r.recipe_id = "rec";
  r.recipe_version = 1;
  r.recipe_hash = std::string(64, 'c');
  r.software_version = "v";
  r.started_at = at;
  r.finished_at = at;
  r.outcome = outcome;
  return r;
}

TeardownEntry Finding(const std::string& serial, TeardownFinding found, const std::string& by,
                      const std::string& at, const std::string& note = "") {
  TeardownEntry e;
  e.serial = serial;
  e.found = found;
  e.by = by;
  e.at = at;
  e.note = note;
  return e;
}

// sqlite3_exec's result and message, for statements that must fail.
std::pair<int, std::string> RawExec(const std::string& path, const std::string& sql) {
  sqlite3* raw = nullptr;
  EXPECT_EQ(sqlite3_open(path.c_str(), &raw), SQLITE_OK);
  char* err = nullptr;
  const int rc = sqlite3_exec(raw, sql.c_str(), nullptr, nullptr, &err);
  std::string message = err ? err : "";
  sqlite3_free(err);
  sqlite3_close(raw);
  return {rc, message};
}

TEST(StoreTeardown, FindingsKeepTheirHistoryAndTheNewestIsCurrent) {
  eol::testing::TempDir dir;
  auto store = Store::Open(dir / "s.sqlite");
  TestRecord first = Record("M-1", "2026-01-01T08:00:00.000Z", Outcome::kFail);
  TestRecord retest = Record("M-1", "2026-01-01T08:05:00.000Z", Outcome::kFail);
  TestRecord other = Record("M-2", "2026-01-01T08:10:00.000Z", Outcome::kPass);
  store->Insert(first);
  store->Insert(retest);
  store->Insert(other);

  const TeardownEntry a = store->AppendTeardown(Finding(
      "M-1", TeardownFinding::kDefective, "Ada", "2026-01-02T09:00:00.000Z", "chipped magnet"));
  EXPECT_GT(a.id, 0);
  ASSERT_TRUE(a.test_id);
  EXPECT_EQ(*a.test_id, retest.id);  // the newest test's verdict is the one judged
  EXPECT_FALSE(a.corrects);
  const TeardownEntry b = store->AppendTeardown(Finding(
      "M-1", TeardownFinding::kNotDefective, "Bob", "2026-01-02T10:00:00.000Z", "re-measured"));
  ASSERT_TRUE(b.corrects);
  EXPECT_EQ(*b.corrects, a.id);
  store->AppendTeardown(
      Finding("M-2", TeardownFinding::kDefective, "Ada", "2026-01-03T09:00:00.000Z"));

  const auto history = store->TeardownsOfSerial("M-1");
  ASSERT_EQ(history.size(), 2u);
  EXPECT_EQ(history[0].by, "Ada");
  EXPECT_EQ(history[0].found, TeardownFinding::kDefective);
  EXPECT_EQ(history[0].note, "chipped magnet");
  EXPECT_EQ(history[0].at, "2026-01-02T09:00:00.000Z");
  EXPECT_EQ(history[1].by, "Bob");
  EXPECT_EQ(history[1].found, TeardownFinding::kNotDefective);

  const auto current = store->CurrentTeardowns();
  ASSERT_EQ(current.size(), 2u);
  EXPECT_EQ(current[0].serial, "M-1");
  EXPECT_EQ(current[0].found, TeardownFinding::kNotDefective);
  EXPECT_EQ(current[1].serial, "M-2");
  EXPECT_EQ(current[1].found, TeardownFinding::kDefective);
  EXPECT_TRUE(store->TeardownsOfSerial("M-404").empty());
}

TEST(StoreTeardown, RefusesUnknownSerialsAndNamelessEntriesBeforeWriting) {
  eol::testing::TempDir dir;
  auto store = Store::Open(dir / "s.sqlite");
  TestRecord r = Record("M-1", "2026-01-01T08:00:00.000Z", Outcome::kFail);
  store->Insert(r);
  try {
    store->AppendTeardown(
        Finding("M-9", TeardownFinding::kDefective, "Ada", "2026-01-02T09:00:00.000Z"));
    FAIL() << "a serial the store never tested was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no finished test of that serial"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(store->AppendTeardown(
                   Finding("M-1", TeardownFinding::kDefective, "  ", "2026-01-02T09:00:00.000Z")),
               std::invalid_argument);
  EXPECT_THROW(store->AppendTeardown(Finding("M-1", TeardownFinding::kDefective, "Ada", "")),
               std::invalid_argument);
  EXPECT_TRUE(store->CurrentTeardowns().empty());
  EXPECT_TRUE(store->write_failure().empty());
}

TEST(StoreTeardown, TheFileRefusesUpdatesAndDeletes) {
  eol::testing::TempDir dir;
  const std::string path = dir / "s.sqlite";
  {
    auto store = Store::Open(path);
    TestRecord r = Record("M-1", "2026-01-01T08:00:00.000Z", Outcome::kFail);
    store->Insert(r);
    store->AppendTeardown(
        Finding("M-1", TeardownFinding::kDefective, "Ada", "2026-01-02T09:00:00.000Z"));
  }
  for (const std::string sql : {"UPDATE teardowns SET found = 'not_defective'",
                                "UPDATE teardowns SET by = 'Eve'", "DELETE FROM teardowns"}) {
    const auto [rc, message] = RawExec(path, sql);
    EXPECT_NE(rc, SQLITE_OK) << sql;
    EXPECT_NE(message.find("append-only"), std::string::npos) << sql << ": " << message;
  }
  auto store = Store::Open(path, Store::Role::kReadOnly);
  const auto history = store->TeardownsOfSerial("M-1");
  ASSERT_EQ(history.size(), 1u);
  EXPECT_EQ(history[0].by, "Ada");
  EXPECT_EQ(history[0].found, TeardownFinding::kDefective);
}

TEST(StoreTeardown, VersionSixFileUpgradesAndTakesFindings) {
  eol::testing::TempDir dir;
  const std::string path = dir / "v6.sqlite";
  {
    std::string sql;
    for (const char* step : {schema::kSchemaV1, schema::kSchemaV2, schema::kSchemaV3,
                             schema::kSchemaV4, schema::kSchemaV5, schema::kSchemaV6})
      sql += step;
    sql += "PRAGMA application_id = " + std::to_string(schema::kApplicationId) +
           "; PRAGMA user_version = 6;"
           "INSERT INTO tests (serial, station_id, recipe_id, recipe_version, recipe_hash, "
           "software_version, started_at, finished_at, outcome, reasons) VALUES ('OLD-6', 's', "
           "'r', 1, 'h', 'v', '2025-01-01T00:00:00.000Z', '2025-01-01T00:00:01.000Z', 'FAIL', "
           "'[]')";
    ASSERT_EQ(RawExec(path, sql).first, SQLITE_OK) << RawExec(path, "SELECT 1").second;
  }
  // A read-only reader refuses the old version; the station's writer migrates it.
  EXPECT_THROW(Store::Open(path, Store::Role::kReadOnly), StoreError);
  auto store = Store::Open(path);
  ASSERT_EQ(store->TestsOfSerial("OLD-6").size(), 1u);
  const TeardownEntry e = store->AppendTeardown(
      Finding("OLD-6", TeardownFinding::kDefective, "Ada", "2026-01-02T09:00:00.000Z"));
  EXPECT_EQ(store->TeardownsOfSerial("OLD-6").size(), 1u);
  EXPECT_TRUE(e.test_id);
}

TEST(StoreTeardown, FindingWordsRoundTrip) {
  for (TeardownFinding f : {TeardownFinding::kDefective, TeardownFinding::kNotDefective})
    EXPECT_EQ(ParseTeardownFinding(ToString(f)), f);
  EXPECT_EQ(ParseTeardownFinding("not_defective"), TeardownFinding::kNotDefective);
  EXPECT_FALSE(ParseTeardownFinding("broken"));
  EXPECT_FALSE(ParseTeardownFinding(""));
}

}  // namespace
}  // namespace eol::db
