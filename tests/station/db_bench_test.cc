// `eol db-bench` (station/bench/db_bench.h): a generated store holds every test, its serials
// are found again, one day's export returns that day's tests, and the size figures add up.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "../support/child_process.h"
#include "db/store.h"

namespace eol::station {
namespace {

using testing::ChildProcess;

// A station store of `units` demo tests (fast recipe, simulated fixture): db-bench's template.
std::string DemoTemplate(const testing::TempDir& dir, const char* units) {
  const std::string tpl = dir / "template.sqlite";
  ChildProcess demo(
      {EOL_BINARY, "demo", "--units", units, "--db", tpl, "--port", "0", "--fixture", "sim"});
  EXPECT_EQ(demo.Wait(std::chrono::seconds(300)), 0) << demo.output();
  return tpl;
}

TEST(DbBench, GeneratedStoreHoldsEveryTestAndItsFiguresAddUp) {
  testing::TempDir dir;
  const std::string tpl = DemoTemplate(dir, "2");
  const std::string db = dir / "bench.sqlite";
  ChildProcess bench({EOL_BINARY, "db-bench", "--template", tpl, "--db", db, "--tests", "3000",
                      "--batch", "700", "--queries", "50", "--json"},
                     /*merge_stderr=*/false);
  ASSERT_EQ(bench.Wait(std::chrono::seconds(300)), 0) << bench.output();
  const nlohmann::json s = nlohmann::json::parse(bench.output());
  EXPECT_EQ(s["tests"], 3000);
  EXPECT_EQ(s["template_serial"], "DEMO-1-0002");
  // 3000 tests at one per 10 s span 8.3 hours of the first day: its export is all of them.
  EXPECT_EQ(s["day_tests"], 3000);
  auto store = db::Store::Open(db, db::Store::Role::kReadOnly);
  const auto one = store->TestsOfSerial("DBB-000000001", /*with_curves=*/true);
  ASSERT_FALSE(one.empty());
  EXPECT_EQ(one.back().started_at, "2026-01-01T00:00:00.000Z");
  EXPECT_FALSE(one.back().curves.empty());
  EXPECT_EQ(s["day_measurement_rows"].get<std::int64_t>(),
            3000 * static_cast<std::int64_t>(one.back().measurements.size()));
  const double bytes = static_cast<double>(std::filesystem::file_size(db));
  EXPECT_NEAR(s["bytes_per_test"].get<double>(), bytes / 3000.0, 0.2 * bytes / 3000.0);
  EXPECT_NEAR(s["growth_gb_per_year"].get<double>(),
              s["bytes_per_test"].get<double>() * 3155760.0 / 1e9, 1e-6);
  EXPECT_GT(s["history_median_ms"].get<double>(), 0.0);
  // Never overwrites a store.
  ChildProcess again({EOL_BINARY, "db-bench", "--template", tpl, "--db", db, "--tests", "10"});
  EXPECT_EQ(again.Wait(std::chrono::seconds(60)), 2);
  EXPECT_NE(again.output().find("exists"), std::string::npos) << again.output();
}

// --replicate: the generated block copied inside SQLite; each copy is its own serials later in
// time with the same bytes, read back through the Store like any test.
TEST(DbBench, ReplicatedBlocksAreNewSerialsLaterInTimeWithTheSameRecords) {
  testing::TempDir dir;
  const std::string tpl = DemoTemplate(dir, "1");
  const std::string db = dir / "bench.sqlite";
  // 400 tests at one per 10 s, no retests: units DBB-1..400 span 4000 s; three blocks.
  ChildProcess bench({EOL_BINARY, "db-bench", "--template", tpl, "--db", db, "--tests", "400",
                      "--retest-share", "0", "--replicate", "3", "--queries", "30", "--json"},
                     /*merge_stderr=*/false);
  ASSERT_EQ(bench.Wait(std::chrono::seconds(300)), 0) << bench.output();
  const nlohmann::json s = nlohmann::json::parse(bench.output());
  EXPECT_EQ(s["tests"], 1200);
  EXPECT_EQ(s["generated"], 400);
  EXPECT_EQ(s["day_tests"], 1200);
  auto store = db::Store::Open(db, db::Store::Role::kReadOnly);
  const auto original = store->TestsOfSerial("DBB-000000007", /*with_curves=*/true);
  const auto copy = store->TestsOfSerial("DBB-000000807", /*with_curves=*/true);
  ASSERT_EQ(original.size(), 1u);
  ASSERT_EQ(copy.size(), 1u);
  EXPECT_EQ(original[0].id, 7);
  EXPECT_EQ(copy[0].id, 807);
  EXPECT_EQ(original[0].started_at, "2026-01-01T00:01:00.000Z");
  EXPECT_EQ(copy[0].started_at, "2026-01-01T02:14:20.000Z");  // + 2 x 4000 s
  ASSERT_EQ(copy[0].measurements.size(), original[0].measurements.size());
  for (std::size_t k = 0; k < copy[0].measurements.size(); ++k) {
    EXPECT_EQ(copy[0].measurements[k].name, original[0].measurements[k].name);
    EXPECT_EQ(copy[0].measurements[k].value, original[0].measurements[k].value);
  }
  ASSERT_EQ(copy[0].curves.size(), original[0].curves.size());
  EXPECT_EQ(copy[0].curves.front().re, original[0].curves.front().re);
  EXPECT_TRUE(store->TestsOfSerial("DBB-000001201").empty());
  EXPECT_EQ(store->MeasurementRows({}).size(), 1200 * original[0].measurements.size());
}

}  // namespace
}  // namespace eol::station
