// `eol query` and `eol export` on a real store, through the binary.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
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
    b.work = {"op-17", "B", "PO-4711"};
    c.work = {"op-2", "night", "PO-9, \"rush\""};
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
  EXPECT_EQ(header.rfind("schema_version,id,serial,station_id,started_at", 0), 0u) << header;
  EXPECT_NE(header.find(",resonance_f_hz_value,resonance_f_hz_sigma,resonance_f_hz_lo,"
                        "resonance_f_hz_hi,resonance_f_hz_unit,resonance_f_hz_outcome,"),
            std::string::npos)
      << header;
  int rows = 0;
  while (std::getline(in, line)) ++rows;
  EXPECT_EQ(rows, 3);
  EXPECT_NE(r.out.find("\"resonance_f_hz = 352 Hz, below 370, \"\"low\"\"\""), std::string::npos);
}

// --all reads the store a page at a time, each page after the last test written (keyset
// paging on started_at, then id): with pages of 4 over 23 more tests, seven of them started in
// the same millisecond, every test comes exactly once and in the order one large page gives.
TEST_F(QueryExportTest, ExportAllPagesThroughEveryTestOnceInOrder) {
  {
    auto store = db::Store::Open(db_);
    for (int i = 0; i < 23; ++i) {
      const std::string t = i < 7 ? "2026-11-22T10:00:00.000Z"
                                  : "2026-11-22T11:" + std::string(i < 10 ? "0" : "") +
                                        std::to_string(i) + ":00.000Z";
      db::TestRecord r = Record("PG-" + std::to_string(i), t, analysis::Outcome::kPass, 390.0 + i);
      store->Insert(r);
    }
  }
  auto ids = [](const std::string& out) {
    std::vector<std::int64_t> v;
    for (const auto& t : nlohmann::json::parse(out)) v.push_back(t["id"].get<std::int64_t>());
    return v;
  };
  const CliRun one = Eol({"export", "--db", db_, "--format", "json", "--limit", "1000"});
  ASSERT_EQ(one.code, 0) << one.out;
  const CliRun paged =
      Eol({"export", "--db", db_, "--format", "json", "--all", "--page-size", "4"});
  ASSERT_EQ(paged.code, 0) << paged.out;
  const std::vector<std::int64_t> want = ids(one.out), got = ids(paged.out);
  EXPECT_EQ(want.size(), 26u);
  EXPECT_EQ(got, want);
  for (const char* format : {"csv", "records"}) {
    const CliRun all =
        Eol({"export", "--db", db_, "--format", format, "--all", "--page-size", "5"});
    ASSERT_EQ(all.code, 0) << all.out;
    if (std::string(format) == "records") {
      EXPECT_EQ(ids(all.out), want);
    } else {
      EXPECT_EQ(std::count(all.out.begin(), all.out.end(), '\n'), 27) << "header + 26 rows";
    }
  }
  EXPECT_NE(Eol({"export", "--db", db_, "--all", "--limit", "5"}).code, 0)
      << "--all and --limit exclude each other";
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

TEST_F(QueryExportTest, QueryAndExportShowWhoTestedAndForWhichOrder) {
  const CliRun q = Eol({"query", "--db", db_, "--serial", "SN-1", "--json"});
  ASSERT_EQ(q.code, 0) << q.out;
  const auto j = nlohmann::json::parse(q.out);
  EXPECT_EQ(j["tests"][0]["operator_id"], "op-17");
  EXPECT_EQ(j["tests"][0]["shift"], "B");
  EXPECT_EQ(j["tests"][0]["order_number"], "PO-4711");
  EXPECT_EQ(j["tests"][1]["operator_id"], "") << "the first test was given none";
  const CliRun text = Eol({"query", "--db", db_, "--serial", "SN-1"});
  EXPECT_NE(text.out.find("operator op-17, shift B, order PO-4711"), std::string::npos) << text.out;

  const CliRun csv = Eol({"export", "--db", db_, "--format", "csv"});
  ASSERT_EQ(csv.code, 0) << csv.out;
  EXPECT_NE(csv.out.find(",retest_of,operator_id,shift,order_number,"), std::string::npos)
      << csv.out;
  EXPECT_NE(csv.out.find(",op-2,night,\"PO-9, \"\"rush\"\"\","), std::string::npos) << csv.out;

  const CliRun order = Eol({"export", "--db", db_, "--format", "json", "--order", "PO-4711"});
  ASSERT_EQ(order.code, 0) << order.out;
  const auto po = nlohmann::json::parse(order.out);
  ASSERT_EQ(po.size(), 1u);
  EXPECT_EQ(po[0]["serial"], "SN-1");
  EXPECT_EQ(po[0]["operator_id"], "op-17");
}

// The CSV read back by an independent reader (Python's csv module): one dict per row.
nlohmann::json ReadCsvWithPython(const std::string& path) {
  const std::string script =
      "import csv, json, sys\n"
      "with open(sys.argv[1], newline='') as f:\n"
      "    print(json.dumps(list(csv.DictReader(f))))\n";
  ChildProcess p({"/usr/bin/env", "python3", "-c", script, path}, false);
  EXPECT_EQ(p.Wait(60s).value_or(-1), 0) << p.output();
  return nlohmann::json::parse(p.output());
}

std::string FirstLine(const std::string& s) { return s.substr(0, s.find('\n')); }

TEST_F(QueryExportTest, CsvHeaderIsTheSameForDatabasesWithDifferentData) {
  // A second station that only ever had ERROR tests: no measurement, no limit, no condition.
  const std::string errors_db = dir_ / "errors.sqlite";
  {
    auto store = db::Store::Open(errors_db);
    db::TestRecord e;
    e.serial = "SN-9";
    e.station_id = "s2";
    e.started_at = e.finished_at = "2026-11-22T08:00:00.000Z";
    e.outcome = analysis::Outcome::kError;
    e.reasons.push_back({analysis::ReasonCode::kFixture, "fixture did not answer"});
    store->Insert(e);
  }
  const CliRun a = Eol({"export", "--db", db_});
  const CliRun b = Eol({"export", "--db", errors_db});
  ASSERT_EQ(a.code, 0) << a.out;
  ASSERT_EQ(b.code, 0) << b.out;
  EXPECT_EQ(FirstLine(a.out), FirstLine(b.out));
  // And the header is the documented one: the same as `eol export --schema` lists.
  const CliRun schema = Eol({"export", "--schema"});
  ASSERT_EQ(schema.code, 0) << schema.out;
  std::string names;
  std::istringstream lines(schema.out);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("| `", 0) != 0) continue;
    names += (names.empty() ? "" : ",") + line.substr(3, line.find('`', 3) - 3);
  }
  EXPECT_EQ(FirstLine(a.out), names);

  const CliRun ej = Eol({"export", "--db", errors_db, "--json"});
  ASSERT_EQ(ej.code, 0) << ej.out;
  const auto rows = nlohmann::json::parse(ej.out);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0]["reason_code"], "fixture");
  EXPECT_TRUE(rows[0]["measurements"]["resonance_f_hz"]["value"].is_null());
}

TEST_F(QueryExportTest, CsvReadByPythonRoundTripsValuesLimitsOutcomesAndText) {
  {
    auto store = db::Store::Open(db_);
    auto r = Record("SN-3", "2026-11-21T10:00:00.000Z", analysis::Outcome::kFail, 361.123456789);
    r.reasons.front().text = "line one, with a comma\nline two \"quoted\"";
    r.work = {"op, 1", "A", "PO-\"7\""};
    r.conditions.clamp_pressure_bar = 5.1;
    r.conditions.winding_temperature_c = 24.25;
    store->Insert(r);
  }
  const std::string csv = dir_ / "out.csv";
  const CliRun r = Eol({"export", "--db", db_, "--out", csv, "--serial", "SN-3"});
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json rows = ReadCsvWithPython(csv);
  ASSERT_EQ(rows.size(), 1u) << rows.dump();
  const auto& row = rows[0];
  EXPECT_EQ(row["reason_text"], "line one, with a comma\nline two \"quoted\"");
  EXPECT_EQ(row["reason_code"], "limit");
  EXPECT_EQ(row["operator_id"], "op, 1");
  EXPECT_EQ(row["order_number"], "PO-\"7\"");
  EXPECT_EQ(std::stod(row["resonance_f_hz_value"].get<std::string>()), 361.123456789);
  EXPECT_EQ(row["resonance_f_hz_sigma"], "0.1");
  EXPECT_EQ(row["resonance_f_hz_lo"], "370");
  EXPECT_EQ(row["resonance_f_hz_hi"], "") << "open upper limit";
  EXPECT_EQ(row["resonance_f_hz_unit"], "Hz");
  EXPECT_EQ(row["resonance_f_hz_outcome"], "FAIL");
  EXPECT_EQ(row["outcome"], "FAIL");
  EXPECT_EQ(row["clamp_pressure_bar"], "5.1");
  EXPECT_EQ(row["winding_temperature_c"], "24.25");
  EXPECT_EQ(row["resonance_q_value"], "") << "declared, not measured";

  // JSON: the same fields as objects, the same value.
  const CliRun j = Eol({"export", "--db", db_, "--format", "json", "--serial", "SN-3"});
  ASSERT_EQ(j.code, 0) << j.out;
  const auto jr = nlohmann::json::parse(j.out).at(0);
  EXPECT_EQ(jr["measurements"]["resonance_f_hz"]["value"].get<double>(), 361.123456789);
  EXPECT_EQ(jr["measurements"]["resonance_f_hz"]["lo"], 370.0);
  EXPECT_EQ(jr["reason_text"], row["reason_text"]);
  EXPECT_EQ(jr.size(), row.size() - 10 * 6 + 1) << "base fields plus \"measurements\"";
}

TEST_F(QueryExportTest, RecipeDeclaresItsMaskColumnsAndRecordsKeepCurves) {
  const CliRun s = Eol({"export", "--schema", "--recipe", "recipes/pmsm-10pole.json"});
  ASSERT_EQ(s.code, 0) << s.out;
  EXPECT_NE(s.out.find("| `mask_re_z_low_band_lines_outside_outcome` | text |"), std::string::npos)
      << s.out;
  const CliRun rec = Eol({"export", "--db", db_, "--format", "records", "--serial", "SN-2"});
  ASSERT_EQ(rec.code, 0) << rec.out;
  const auto j = nlohmann::json::parse(rec.out);
  ASSERT_EQ(j.size(), 1u);
  EXPECT_TRUE(j[0]["measurements"].is_array()) << "a full record";
  const CliRun outcome = Eol({"export", "--db", db_, "--json", "--outcome", "FAIL"});
  ASSERT_EQ(outcome.code, 0) << outcome.out;
  EXPECT_EQ(nlohmann::json::parse(outcome.out).size(), 1u);
  // Rows of the schema are not records: teach says which format it reads.
  const std::string rows = dir_ / "rows.json";
  ASSERT_EQ(Eol({"export", "--db", db_, "--json", "--out", rows}).code, 0);
  const CliRun teach = testing::RunEol({"teach", "--recipe", "recipes/pmsm-10pole.json", "--golden",
                                        rows, "--out", dir_ / "taught.json"},
                                       true, 60s);
  EXPECT_EQ(teach.code, 2) << teach.out;
  EXPECT_NE(teach.out.find("eol export --format records"), std::string::npos) << teach.out;
}

TEST(ExportSchemaDocs, TheReadmeTableIsWhatTheCommandPrints) {
  std::ifstream in(std::string(EOL_SOURCE_DIR) + "/deploy/OPERATIONS.md");
  const std::string readme((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string begin = "<!-- export-schema:begin -->\n", end = "<!-- export-schema:end -->";
  const auto b = readme.find(begin), e = readme.find(end);
  ASSERT_NE(b, std::string::npos);
  ASSERT_NE(e, std::string::npos);
  const CliRun s = Eol({"export", "--schema"});
  ASSERT_EQ(s.code, 0) << s.out;
  EXPECT_EQ(readme.substr(b + begin.size(), e - b - begin.size()), s.out)
      << "deploy/OPERATIONS.md's export schema table differs from `eol export --schema`";
}

TEST_F(QueryExportTest, MissingDatabaseNamesThePath) {
  const CliRun r = Eol({"export", "--db", dir_ / "missing.sqlite"});
  EXPECT_NE(r.code, 0);
}

// Everything in `dir`: names, sizes and contents, to see that a command changed nothing.
std::map<std::string, std::string> Snapshot(const std::string& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    std::ifstream in(e.path(), std::ios::binary);
    files[e.path().filename().string()] =
        std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  return files;
}

TEST_F(QueryExportTest, ReadOnlyCommandsNeverModifyTheDatabase) {
  const auto before = Snapshot(dir_.path());
  EXPECT_EQ(Eol({"query", "--db", db_, "--serial", "SN-1", "--json"}).code, 0);
  EXPECT_EQ(Eol({"export", "--db", db_, "--format", "csv"}).code, 0);
  EXPECT_EQ(Eol({"stats", "--db", db_}).code, 0);
  EXPECT_TRUE(Snapshot(dir_.path()) == before) << "a read-only command changed " << dir_.path();
}

TEST(ReadOnlyCommands, AFileThatIsNotAStoreIsRefusedAndLeftAlone) {
  eol::testing::TempDir dir;
  std::ofstream(dir / "empty.sqlite").close();
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"query", "--db", dir / "empty.sqlite", "--serial", "A-1"},
        std::vector<std::string>{"export", "--db", dir / "empty.sqlite"},
        std::vector<std::string>{"stats", "--db", dir / "empty.sqlite"}}) {
    const CliRun r = testing::RunEol(args, true, 60s);
    EXPECT_EQ(r.code, 2) << args[0] << ": " << r.out;
    EXPECT_NE(r.out.find("not an EOL test store"), std::string::npos) << args[0] << ": " << r.out;
  }
  EXPECT_EQ(std::filesystem::file_size(dir / "empty.sqlite"), 0u) << "a schema was written";
  EXPECT_EQ(Snapshot(dir.path()).size(), 1u) << "journal files were created";
}

TEST(CliExitCodes, UsageErrorsExitTwo) {
  eol::testing::TempDir dir;
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{}, std::vector<std::string>{"query", "--no-such-option"},
        std::vector<std::string>{"query", "--serial", "A-1"},
        std::vector<std::string>{"query", "--db", dir / "missing.sqlite", "--serial", "A-1"},
        std::vector<std::string>{"export", "--db", dir / "missing.sqlite", "--limit", "10abc"},
        std::vector<std::string>{"no-such-command"}}) {
    const CliRun r = testing::RunEol(args, true, 60s);
    EXPECT_EQ(r.code, 2) << (args.empty() ? "(none)" : args[0]) << ": " << r.out;
  }
  EXPECT_EQ(testing::RunEol({"query", "--help"}, true, 60s).code, 0);
  EXPECT_FALSE(std::filesystem::exists(dir / "missing.sqlite"));
}

}  // namespace
}  // namespace eol
