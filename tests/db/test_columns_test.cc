// The one list of a test's columns (db/test_columns.h) against the tests table of a real store
// file (PRAGMA table_info), so the list and the schema's migrations (db/schema.h) cannot
// drift; every stored column round-trips through the store's derived INSERT, UPDATE and row
// reader; the export's base columns are the list's exported entries. The central table is
// checked against the list in tests/station/central_record_test.cc.
#include "db/test_columns.h"

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <filesystem>
#include <map>
#include <set>
#include <string>

#include "../support/child_process.h"
#include "db/export_schema.h"
#include "db/last_verdict.h"
#include "db/store.h"

namespace eol::db {
namespace {

// name -> declared type of every column of the store's tests table.
std::map<std::string, std::string> TableInfo(const std::string& path) {
  sqlite3* raw = nullptr;
  EXPECT_EQ(sqlite3_open_v2(path.c_str(), &raw, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  sqlite3_stmt* s = nullptr;
  EXPECT_EQ(sqlite3_prepare_v2(raw, "PRAGMA table_info(tests)", -1, &s, nullptr), SQLITE_OK);
  std::map<std::string, std::string> out;
  while (sqlite3_step(s) == SQLITE_ROW)
    out[reinterpret_cast<const char*>(sqlite3_column_text(s, 1))] =
        reinterpret_cast<const char*>(sqlite3_column_text(s, 2));
  sqlite3_finalize(s);
  sqlite3_close(raw);
  return out;
}

TEST(TestColumns, TheStoredOnesAreExactlyTheColumnsOfTheStoresTestsTable) {
  eol::testing::TempDir dir;
  const std::string path = dir / "store.sqlite";
  Store::Open(path);  // created and migrated to Store::kSchemaVersion
  const std::map<std::string, std::string> table = TableInfo(path);
  ASSERT_FALSE(table.empty());
  std::map<std::string, std::string> listed;
  for (const TestColumn& c : TestColumns())
    if (c.store != StoreWrite::kNone) listed[c.name] = c.sql_type;
  EXPECT_EQ(listed, table) << "db/test_columns.cc and db/schema.h disagree";
}

TEST(TestColumns, EachEntryIsComplete) {
  std::set<std::string> names, central;
  for (const TestColumn& c : TestColumns()) {
    SCOPED_TRACE(c.name);
    EXPECT_TRUE(names.insert(c.name).second) << "listed twice";
    EXPECT_NE(c.get, nullptr);
    EXPECT_NE(std::string(c.doc), "");
    EXPECT_LE(c.export_since, kExportSchemaVersion);
    EXPECT_EQ(c.store == StoreWrite::kNone, c.set == nullptr);
    EXPECT_EQ(c.store == StoreWrite::kNone, std::string(c.sql_type).empty());
    EXPECT_EQ(c.central_name == nullptr, c.central_type == nullptr);
    if (c.central_name != nullptr) {
      EXPECT_TRUE(central.insert(c.central_name).second);
    }
  }
  EXPECT_EQ(&TestColumnNamed("serial"), &TestColumns()[1]);
  EXPECT_THROW(TestColumnNamed("no_such_column"), std::out_of_range);
}

// A record with every stored field set, none to its default.
TestRecord Full(const std::string& serial) {
  TestRecord r;
  r.serial = serial;
  r.station_id = "st-7";
  r.recipe_id = "pmsm";
  r.recipe_version = 4;
  r.recipe_hash = std::string(64, 'e');
  r.software_version = "1.2.3";
  r.started_at = "2026-03-01T10:00:00.000Z";
  r.finished_at = "2026-03-01T10:00:05.250Z";
  r.outcome = analysis::Outcome::kFail;
  r.reasons = {{analysis::ReasonCode::kLimit, "resonance_f_hz above 410 Hz"},
               {analysis::ReasonCode::kMask, "impedance outside its mask"}};
  analysis::Measurement m;
  m.name = "resonance_f_hz";
  m.unit = "Hz";
  m.value = 411.25;
  m.sigma = 0.5;
  r.measurements.push_back(m);
  r.max_tests = 3;
  r.kind = RecordKind::kSelfCheck;
  r.self_check = {{"master", "limit"}, {"passed", true}, {"detail", "failed as it must"}};
  r.work = {"op-1", "night", "PO-9"};
  return r;
}

TEST(TestColumns, EveryStoredColumnRoundTripsThroughTheStore) {
  eol::testing::TempDir dir;
  auto store = Store::Open(dir / "store.sqlite");
  TestRecord first = Full("SN-1");
  store->Insert(first);
  TestRecord retest = Full("SN-1");
  store->Insert(retest);
  ASSERT_TRUE(retest.retest_of.has_value());
  const std::optional<TestRecord> read = store->Test(retest.id, /*with_curves=*/false);
  ASSERT_TRUE(read.has_value());
  EXPECT_EQ(read->attempt, 2);
  int stored = 0;
  for (const TestColumn& c : TestColumns()) {
    if (c.store == StoreWrite::kNone) continue;
    ++stored;
    EXPECT_EQ(c.get(*read), c.get(retest)) << c.name;
  }
  EXPECT_EQ(stored, static_cast<int>(TestColumns().size()) - 3);  // not the reason_* columns
}

TEST(TestColumns, TheExportsBaseColumnsAreTheExportedEntriesInListOrder) {
  std::vector<std::string> listed;
  for (const TestColumn& c : TestColumns())
    if (c.export_since > 0) listed.push_back(c.name);
  const std::vector<ExportColumn> columns = ExportColumns({});
  ASSERT_GT(columns.size(), listed.size());
  // After schema_version, in the list's order; then the conditions.
  std::vector<std::string> exported;
  for (std::size_t i = 1; i <= listed.size(); ++i) exported.push_back(columns[i].name);
  EXPECT_EQ(exported, listed);
  const TestRecord r = Full("SN-2");
  EXPECT_EQ(std::get<std::string>(columns[1 + 5].get(r)), "FAIL");  // outcome
}

// What reading back a test says after `sql` changed its stored row.
std::string ReadAfter(const std::string& sql) {
  eol::testing::TempDir dir;
  const std::string path = dir / "store.sqlite";
  std::int64_t id = 0;
  {
    auto store = Store::Open(path);
    TestRecord r = Full("SN-3");
    store->Insert(r);
    id = r.id;
  }
  sqlite3* raw = nullptr;
  EXPECT_EQ(sqlite3_open(path.c_str(), &raw), SQLITE_OK);
  EXPECT_EQ(sqlite3_exec(raw, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK)
      << sqlite3_errmsg(raw);
  sqlite3_close(raw);
  // The changed outcome is not a lost verdict here: the store is not to compare it.
  std::filesystem::remove(LastVerdictPath(path));
  try {
    Store::Open(path)->Test(id, false);
  } catch (const StoreError& e) {
    return e.what();
  }
  return "read test " + std::to_string(id) + " without an error";
}

void ExpectHas(const std::string& text, const std::string& part) {
  EXPECT_NE(text.find(part), std::string::npos) << text;
}

TEST(TestColumns, AStoredValueThatIsNotARecordsIsAnErrorNamingTheTestAndTheColumn) {
  // (An unknown kind or outcome cannot get this far: the schema's CHECKs refuse it, and the
  // store's quick_check at open refuses a file that holds one anyway.)
  ExpectHas(ReadAfter("UPDATE tests SET reasons = '{'"),
            "read test 1: stored JSON is not a record (column reasons)");
  ExpectHas(ReadAfter("UPDATE tests SET record = '[1]'"),
            "read test 1: stored JSON is not a record (column record)");
}

}  // namespace
}  // namespace eol::db
