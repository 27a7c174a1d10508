// Schema version 3: test kinds, the self_checks table written with its test in one
// transaction, measurement rows for statistics, and a version-2 file upgrading in place.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <filesystem>
#include <string>

#include "../support/child_process.h"
#include "db/schema.h"
#include "db/store.h"

namespace eol::db {
namespace {

using analysis::Outcome;

TestRecord Record(const std::string& serial, const std::string& at, Outcome outcome, double f0_hz,
                  RecordKind kind = RecordKind::kProduction) {
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
  r.kind = kind;
  analysis::Measurement m;
  m.name = "resonance_f_hz";
  m.unit = "Hz";
  m.value = f0_hz;
  m.limit.lo = 370;
  m.limit.hi = 420;
  m.outcome = analysis::MeasurementOutcome::kPass;
  r.measurements.push_back(m);
  return r;
}

void Exec(sqlite3* db, const std::string& sql) {
  char* err = nullptr;
  ASSERT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &err), SQLITE_OK)
      << sql << ": " << (err ? err : "");
}

TEST(StoreV3, VersionTwoFileUpgradesAndOldTestsAreProduction) {
  eol::testing::TempDir dir;
  const std::string path = dir / "v2.sqlite";
  {
    sqlite3* raw = nullptr;
    ASSERT_EQ(sqlite3_open(path.c_str(), &raw), SQLITE_OK);
    Exec(raw, schema::kSchemaV1);
    Exec(raw, schema::kSchemaV2);
    Exec(raw, "PRAGMA application_id = " + std::to_string(schema::kApplicationId) +
                  "; PRAGMA user_version = 2");
    Exec(raw,
         "INSERT INTO tests (serial, station_id, recipe_id, recipe_version, recipe_hash, "
         "software_version, started_at, finished_at, outcome, reasons) VALUES ('OLD-2', 's', "
         "'r', 1, 'h', 'v', '2025-01-01T00:00:00.000Z', '2025-01-01T00:00:01.000Z', 'PASS', '[]')");
    Exec(raw,
         "INSERT INTO measurements (test_id, name, value, unit, lo, hi, outcome, marginal) "
         "VALUES (1, 'resonance_f_hz', 391.5, 'Hz', 370, 420, 'PASS', 0)");
    sqlite3_close(raw);
  }
  auto store = Store::Open(path);
  const auto old = store->TestsOfSerial("OLD-2");
  ASSERT_EQ(old.size(), 1u);
  EXPECT_EQ(old[0].kind, RecordKind::kProduction);
  const auto rows = store->MeasurementRows({});
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].serial, "OLD-2");
  EXPECT_DOUBLE_EQ(*rows[0].value, 391.5);
  EXPECT_DOUBLE_EQ(*rows[0].lo, 370.0);
  EXPECT_TRUE(store->SelfChecks().empty());
  // The upgraded file takes self-checks.
  TestRecord m =
      Record("MASTER-G", "2025-01-02T00:00:00.000Z", Outcome::kPass, 390, RecordKind::kSelfCheck);
  m.self_check = {{"master", "good"}, {"passed", true}, {"detail", "ok"}};
  store->Insert(m);
  ASSERT_EQ(store->SelfChecks().size(), 1u);
}

TEST(StoreV3, SelfChecksAreWrittenWithTheirTestAndKeptApartFromProduction) {
  eol::testing::TempDir dir;
  auto store = Store::Open(dir / "s.sqlite");
  TestRecord p1 = Record("U-1", "2026-01-01T00:00:00.000Z", Outcome::kPass, 390);
  store->Insert(p1);
  TestRecord g =
      Record("MASTER-G", "2026-01-01T01:00:00.000Z", Outcome::kPass, 391, RecordKind::kSelfCheck);
  g.self_check = {{"master", "good"}, {"passed", true}, {"detail", "good master passed"}};
  store->Insert(g);
  TestRecord l =
      Record("MASTER-L", "2026-01-01T02:00:00.000Z", Outcome::kPass, 392, RecordKind::kSelfCheck);
  l.self_check = {{"master", "limit"}, {"passed", false}, {"detail", "limit master PASSed"}};
  store->Insert(l);
  TestRecord p2 = Record("U-2", "2026-01-01T03:00:00.000Z", Outcome::kFail, 350);
  store->Insert(p2);

  const auto checks = store->SelfChecks();
  ASSERT_EQ(checks.size(), 2u);
  EXPECT_EQ(checks[0].master, "limit");
  EXPECT_FALSE(checks[0].passed);
  EXPECT_EQ(checks[0].test_id, l.id);
  EXPECT_EQ(checks[0].detail, "limit master PASSed");
  EXPECT_EQ(store->LatestSelfCheck("good")->serial, "MASTER-G");
  EXPECT_EQ(store->Test(l.id)->kind, RecordKind::kSelfCheck);
  EXPECT_EQ(store->Test(l.id)->self_check["passed"], false);

  EXPECT_EQ(store->CountTestsSince(RecordKind::kProduction, "2026-01-01T00:00:00.000Z"), 2);
  EXPECT_EQ(store->CountTestsSince(RecordKind::kProduction, "2026-01-01T02:00:00.000Z"), 1);
  const auto production = store->MeasurementRows({});
  ASSERT_EQ(production.size(), 2u);
  EXPECT_EQ(production[0].serial, "U-1");
  EXPECT_EQ(production[1].outcome, Outcome::kFail);
  MeasurementQuery masters;
  masters.kind = RecordKind::kSelfCheck;
  EXPECT_EQ(store->MeasurementRows(masters).size(), 2u);
  MeasurementQuery window;
  window.from = "2026-01-01T02:30:00.000Z";
  EXPECT_EQ(store->MeasurementRows(window).size(), 1u);
}

TEST(StoreV3, ASelfCheckRecordWithoutItsResultIsRefusedAndNotStored) {
  eol::testing::TempDir dir;
  auto store = Store::Open(dir / "s.sqlite");
  TestRecord bad =
      Record("MASTER-G", "2026-01-01T01:00:00.000Z", Outcome::kPass, 391, RecordKind::kSelfCheck);
  try {
    store->Insert(bad);
    ADD_FAILURE() << "a self-check without master/passed was stored";
  } catch (const StoreError& e) {
    EXPECT_NE(std::string(e.what()).find("record.self_check needs master and passed"),
              std::string::npos)
        << e.what();
  }
  EXPECT_TRUE(store->TestsOfSerial("MASTER-G").empty());
  // A kind other than production or self_check cannot be built (RecordKind); its string is
  // refused where it enters, by ParseRecordKind (record_json_test.cc).
}

}  // namespace
}  // namespace eol::db
