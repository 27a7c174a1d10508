// Schema version 5: the outbox. Every finished record, and every test recovered as ABORTED,
// gets its row in the record's own transaction; a consumer reads the rows after its cursor in
// order, and its cursor never moves back. A version-4 file upgrades with an empty outbox.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <string>

#include "../support/child_process.h"
#include "db/schema.h"
#include "db/store.h"

namespace eol::db {
namespace {

TestRecord Record(const std::string& serial, const std::string& at) {
  TestRecord r;
  r.serial = serial;
  r.station_id = "S";
  r.recipe_id = "rec";
  r.recipe_version = 1;
  r.recipe_hash = std::string(64, 'c');
  r.software_version = "v";
  r.started_at = at;
  r.finished_at = at;
  r.outcome = analysis::Outcome::kPass;
  return r;
}

TEST(StoreOutbox, EveryStoredRecordQueuesOnceInOrderAndCursorsAreIndependent) {
  eol::testing::TempDir dir;
  auto store = Store::Open(dir / "o.sqlite");
  TestRecord a = Record("A", "2025-01-01T00:00:00.000Z");
  store->Insert(a);
  TestRecord b = Record("B", "2025-01-01T00:01:00.000Z");
  store->BeginTest(b);
  EXPECT_EQ(store->OutboxPending("mqtt"), 1) << "a running test is not in the outbox";
  store->FinishTest(b);
  TestRecord c = Record("C", "2025-01-01T00:02:00.000Z");
  store->Insert(c);

  const auto all = store->OutboxAfterCursor("mqtt", 100);
  ASSERT_EQ(all.size(), 3u);
  EXPECT_EQ(all[0].test_id, a.id);
  EXPECT_EQ(all[1].test_id, b.id);
  EXPECT_EQ(all[2].test_id, c.id);
  EXPECT_LT(all[0].id, all[1].id);
  EXPECT_EQ(all[1].created_at, b.finished_at);

  store->AdvanceOutboxCursor("mqtt", all[1].id);
  EXPECT_EQ(store->OutboxCursor("mqtt"), all[1].id);
  EXPECT_EQ(store->OutboxPending("mqtt"), 1);
  ASSERT_EQ(store->OutboxAfterCursor("mqtt", 100).size(), 1u);
  EXPECT_EQ(store->OutboxAfterCursor("mqtt", 100)[0].test_id, c.id);
  store->AdvanceOutboxCursor("mqtt", all[0].id);  // never back
  EXPECT_EQ(store->OutboxCursor("mqtt"), all[1].id);
  EXPECT_EQ(store->OutboxPending("central"), 3) << "another consumer has its own cursor";
  EXPECT_EQ(store->OutboxCursor("central"), 0);
}

// A refused finish writes none of the record, but the test does not stay RUNNING: it is
// finished as ERROR and queued as such; a test cut short by a crash is recovered
// as ABORTED at the next open and queued then.
TEST(StoreOutbox, AFailedFinishQueuesItsErrorAndRecoveredTestsAreQueued) {
  eol::testing::TempDir dir;
  const std::string path = dir / "o.sqlite";
  std::int64_t refused_id = 0;
  {
    auto store = Store::Open(path);
    TestRecord r = Record("R", "2025-01-01T00:00:00.000Z");
    store->BeginTest(r);
    refused_id = r.id;
    TestRecord bad = r;
    bad.finished_at.clear();  // refused: the transaction is rolled back whole
    EXPECT_THROW(store->FinishTest(bad), StoreError);
    EXPECT_EQ(store->OutboxPending("mqtt"), 1);
    EXPECT_EQ(store->Test(r.id)->outcome, analysis::Outcome::kError);
    TestRecord cut = Record("C", "2025-01-01T00:01:00.000Z");
    store->BeginTest(cut);
  }  // "crash": C stays RUNNING
  auto store = Store::Open(path);
  EXPECT_EQ(store->aborted_on_open(), 1);
  const auto rows = store->OutboxAfterCursor("mqtt", 10);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].test_id, refused_id);
  EXPECT_EQ(store->Test(rows[1].test_id)->outcome, analysis::Outcome::kAborted);
}

TEST(StoreOutbox, AVersionFourFileUpgradesWithAnEmptyOutbox) {
  eol::testing::TempDir dir;
  const std::string path = dir / "v4.sqlite";
  {
    sqlite3* raw = nullptr;
    ASSERT_EQ(sqlite3_open(path.c_str(), &raw), SQLITE_OK);
    for (const char* sql :
         {schema::kSchemaV1, schema::kSchemaV2, schema::kSchemaV3, schema::kSchemaV4})
      ASSERT_EQ(sqlite3_exec(raw, sql, nullptr, nullptr, nullptr), SQLITE_OK);
    const std::string ids = "PRAGMA application_id = " + std::to_string(schema::kApplicationId) +
                            "; PRAGMA user_version = 4";
    ASSERT_EQ(sqlite3_exec(raw, ids.c_str(), nullptr, nullptr, nullptr), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(raw,
                           "INSERT INTO tests (serial, station_id, recipe_id, recipe_version, "
                           "recipe_hash, software_version, started_at, finished_at, outcome) "
                           "VALUES ('OLD', 's', 'r', 1, 'h', 'v', '2025-01-01T00:00:00.000Z', "
                           "'2025-01-01T00:00:01.000Z', 'PASS')",
                           nullptr, nullptr, nullptr),
              SQLITE_OK);
    sqlite3_close(raw);
  }
  auto store = Store::Open(path);
  EXPECT_EQ(store->TestsOfSerial("OLD").size(), 1u);
  EXPECT_EQ(store->OutboxPending("mqtt"), 0) << "records before version 5 are not published";
  TestRecord r = Record("NEW", "2025-01-02T00:00:00.000Z");
  store->Insert(r);
  EXPECT_EQ(store->OutboxPending("mqtt"), 1);
}

}  // namespace
}  // namespace eol::db
