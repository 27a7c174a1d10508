// `eol query` and `eol export` on a real store, through the binary.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "../support/child_process.h"
#include "db/store.h"
#include "tests/support/eol_cli.h"

namespace eol {
namespace {

using namespace std::chrono_literals;
using eol::testing::ChildProcess;

db::TestRecord Record(const std::string& serial, const std::string& t, analysis::Outcome o,
                      double f0) {
  db::TestRecord r;
  r.serial = serial;
  r.station_id = "s1";
  r.recipe_id = "pmsm-10pole";
  r.recipe_version = 1;
  r.recipe_hash = std::string(64, 'a');
  r.software_version = "test";
  r.started_at = t;
  r.finished_at = t;
  r.outcome = o;
  analysis::Measurement m;
  m.name = "resonance_f_hz";
  m.unit = "Hz";
  m.value = f0;
  m.sigma = 0.1;
  m.limit.lo = 370;
  m.outcome = f0 >= 370 ? analysis::MeasurementOutcome::kPass : analysis::MeasurementOutcome::kFail;
  r.measurements.push_back(m);
  if (o == analysis::Outcome::kFail)
    r.reasons.push_back(
        {analysis::ReasonCode::kLimit, "resonance_f_hz = 352 Hz, below 370, \"low\""});
  return r;
}

using eol::testing::CliRun;

CliRun Eol(const std::vector<std::string>& args) { return testing::RunEol(args, false, 60s); }

class QueryExportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto store = db::Store::Open(db_);
    auto a = Record("SN-1", "2026-11-20T08:00:00.000Z", analysis::Outcome::kFail, 352.0);
    auto b = Record("SN-1", "2026-11-21T08:00:00.000Z", analysis::Outcome::kPass, 391.0);
    auto c = Record("SN-2", "2026-11-21T09:00:00.000Z", analysis::Outcome::kPass, 389.5);
    store->Insert(a);
    store->Insert(b);
    store->Insert(c);
  }
  eol::testing::TempDir dir_;
  std::string db_ = dir_ / "q.sqlite";
};

TEST_F(QueryExportTest, QueryShowsHistoryNewestFirstWithRetestLink) {
  const CliRun r = Eol({"query", "--db", db_, "--serial", "SN-1", "--json"});
  ASSERT_EQ(r.code, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["tests"].size(), 2u);
  EXPECT_EQ(j["latest"]["outcome"], "PASS");
  EXPECT_EQ(j["tests"][1]["outcome"], "FAIL");
  EXPECT_EQ(j["tests"][0]["retest_of"], j["tests"][1]["id"]);
  EXPECT_EQ(j["latest"]["recipe"]["hash"], std::string(64, 'a'));

  const CliRun text = Eol({"query", "--db", db_, "--serial", "SN-1"});
  EXPECT_EQ(text.code, 0);
  EXPECT_NE(text.out.find("SN-1: 2 test(s), latest PASS"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("reason (limit): resonance_f_hz = 352 Hz"), std::string::npos)
      << text.out;
}

TEST_F(QueryExportTest, UnknownSerialExitsOneAndBadSerialIsRefused) {
  EXPECT_EQ(Eol({"query", "--db", db_, "--serial", "NOPE"}).code, 1);
  const CliRun bad = Eol({"query", "--db", db_, "--serial", ""});
  EXPECT_EQ(bad.code, 2);
}

TEST_F(QueryExportTest, ExportCsvHasOneRowPerTestAndQuotesReasons) {
  const CliRun r = Eol({"export", "--db", db_, "--format", "csv"});
  ASSERT_EQ(r.code, 0) << r.out;
  std::istringstream in(r.out);
  std::string header, line;
  std::getline(in, header);
  EXPECT_EQ(header.rfind("id,serial,station_id,started_at", 0), 0u) << header;
  EXPECT_NE(header.find(",resonance_f_hz,"), std::string::npos);
  int rows = 0;
  while (std::getline(in, line)) ++rows;
  EXPECT_EQ(rows, 3);
  EXPECT_NE(r.out.find("\"resonance_f_hz = 352 Hz, below 370, \"\"low\"\"\""), std::string::npos);
}

TEST_F(QueryExportTest, ExportJsonBySerialAndTimeRange) {
  const CliRun r = Eol({"export", "--db", db_, "--format", "json", "--from",
                        "2026-11-21T00:00:00.000Z", "--to", "2026-11-22T00:00:00.000Z"});
  ASSERT_EQ(r.code, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.size(), 2u);
  for (const auto& t : j) EXPECT_EQ(t["outcome"], "PASS");
  const CliRun one = Eol({"export", "--db", db_, "--format", "json", "--serial", "SN-2"});
  EXPECT_EQ(nlohmann::json::parse(one.out).size(), 1u);
}

TEST_F(QueryExportTest, MissingDatabaseNamesThePath) {
  const CliRun r = Eol({"export", "--db", dir_ / "missing.sqlite"});
  EXPECT_NE(r.code, 0);
}

}  // namespace
}  // namespace eol
