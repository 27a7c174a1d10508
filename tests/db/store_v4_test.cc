// Schema version 4: who tested and for which order (operator id, shift, order number) stored
// with every record, read back by every query, a version-3 file upgrading in place with its
// old tests left empty, and the JSON round trip of the record.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <string>

#include "../support/child_process.h"
#include "db/schema.h"
#include "db/store.h"

namespace eol::db {
namespace {

using analysis::Outcome;

TestRecord Record(const std::string& serial, const std::string& at, const WorkContext& work) {
  TestRecord r;
  r.serial = serial;
  r.station_id = "S";
  r.recipe_id = "rec";
  r.recipe_version = 1;
  r.recipe_hash = std::string(64, 'c');
  r.software_version = "v";
  r.started_at = at;
  r.finished_at = at;
  r.outcome = Outcome::kPass;
  r.work = work;
  return r;
}

void Exec(sqlite3* db, const std::string& sql) {
  char* err = nullptr;
  ASSERT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &err), SQLITE_OK)
      << sql << ": " << (err ? err : "");
}

TEST(StoreV4, VersionThreeFileUpgradesAndOldTestsHaveNoWorkContext) {
  eol::testing::TempDir dir;
  const std::string path = dir / "v3.sqlite";
  {
    sqlite3* raw = nullptr;
    ASSERT_EQ(sqlite3_open(path.c_str(), &raw), SQLITE_OK);
    Exec(raw, schema::kSchemaV1);
    Exec(raw, schema::kSchemaV2);
    Exec(raw, schema::kSchemaV3);
    Exec(raw, "PRAGMA application_id = " + std::to_string(schema::kApplicationId) +
                  "; PRAGMA user_version = 3");
    Exec(raw,
         "INSERT INTO tests (serial, station_id, recipe_id, recipe_version, recipe_hash, "
         "software_version, started_at, finished_at, outcome, reasons) VALUES ('OLD-3', 's', "
         "'r', 1, 'h', 'v', '2025-01-01T00:00:00.000Z', '2025-01-01T00:00:01.000Z', 'PASS', '[]')");
    sqlite3_close(raw);
  }
  auto store = Store::Open(path);
  const auto old = store->TestsOfSerial("OLD-3");
  ASSERT_EQ(old.size(), 1u);
  EXPECT_EQ(old[0].work, WorkContext{});
  // The upgraded file takes the new fields.
  TestRecord r = Record("NEW-4", "2025-01-02T00:00:00.000Z", {"op-17", "B", "PO-4711"});
  store->Insert(r);
  const auto back = store->TestsOfSerial("NEW-4");
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0].work, (WorkContext{"op-17", "B", "PO-4711"}));
}

TEST(StoreV4, EveryQueryReadsTheWorkContextAndTestsFilterByOrder) {
  eol::testing::TempDir dir;
  auto store = Store::Open(dir / "s.sqlite");
  TestRecord a = Record("A-1", "2025-01-01T00:00:00.000Z", {"op-1", "A", "PO-1"});
  TestRecord b = Record("B-1", "2025-01-01T00:01:00.000Z", {"op-2", "night", "PO-2"});
  TestRecord c = Record("C-1", "2025-01-01T00:02:00.000Z", {});
  store->Insert(a);
  store->Insert(b);
  store->Insert(c);
  // Begin + finish, as the sequencer does: the begin row carries the fields.
  TestRecord d = Record("D-1", "2025-01-01T00:03:00.000Z", {"op-3", "C", "PO-1"});
  store->BeginTest(d);
  store->FinishTest(d);

  EXPECT_EQ(store->Test(a.id)->work, (WorkContext{"op-1", "A", "PO-1"}));
  EXPECT_EQ(store->LatestOfSerial("B-1")->work, (WorkContext{"op-2", "night", "PO-2"}));
  EXPECT_EQ(store->TestsOfSerial("C-1").at(0).work, WorkContext{});
  TestQuery q;
  q.order_number = "PO-1";
  const auto po1 = store->Tests(q);
  ASSERT_EQ(po1.size(), 2u);
  EXPECT_EQ(po1[0].serial, "D-1");
  EXPECT_EQ(po1[0].work.operator_id, "op-3");
  EXPECT_EQ(po1[1].serial, "A-1");
  EXPECT_EQ(store->Tests(TestQuery{}).size(), 4u);
}

TEST(StoreV4, TheColumnsAreAuthoritativeOverTheRecordJson) {
  eol::testing::TempDir dir;
  const std::string path = dir / "s.sqlite";
  std::int64_t id = 0;
  {
    auto store = Store::Open(path);
    TestRecord r = Record("A-1", "2025-01-01T00:00:00.000Z", {"op-1", "A", "PO-1"});
    store->Insert(r);
    id = r.id;
  }
  {
    sqlite3* raw = nullptr;
    ASSERT_EQ(sqlite3_open(path.c_str(), &raw), SQLITE_OK);
    Exec(raw, "UPDATE tests SET operator_id = 'op-9' WHERE id = " + std::to_string(id));
    sqlite3_close(raw);
  }
  auto store = Store::Open(path);
  EXPECT_EQ(store->Test(id)->work.operator_id, "op-9");
}

TEST(WorkContextJson, RoundTripsAsTopLevelKeysAndIsEmptyForOldRecords) {
  TestRecord r = Record("U-1", "2025-01-01T00:00:00.000Z", {"op-1", "A", "PO-1"});
  nlohmann::json j = r;
  EXPECT_EQ(j.at("operator_id"), "op-1");
  EXPECT_EQ(j.at("shift"), "A");
  EXPECT_EQ(j.at("order_number"), "PO-1");
  EXPECT_EQ(j.get<TestRecord>().work, r.work);
  for (const char* key : {"operator_id", "shift", "order_number"}) j.erase(key);
  EXPECT_EQ(j.get<TestRecord>().work, WorkContext{});
}

}  // namespace
}  // namespace eol::db
