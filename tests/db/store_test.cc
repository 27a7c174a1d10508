// Contract tests of db::Store (db/store.h): each test opens a fresh file in its own
// temporary directory, removed afterwards.
#include "db/store.h"

#include <gtest/gtest.h>
#include <sqlite3.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <regex>
#include <string>
#include <vector>

#include "db/schema.h"

namespace eol::db {
namespace {

namespace fs = std::filesystem;
using analysis::Measurement;
using analysis::MeasurementOutcome;
using analysis::Outcome;
using analysis::ReasonCode;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Runs `statement`, which must throw StoreError whose message contains every one of `parts`.
#define EXPECT_STORE_ERROR(statement, ...)                                            \
  do {                                                                                \
    try {                                                                             \
      statement;                                                                      \
      ADD_FAILURE() << #statement " did not throw";                                   \
    } catch (const StoreError& e) {                                                   \
      for (const std::string& part : std::initializer_list<std::string>{__VA_ARGS__}) \
        EXPECT_NE(std::string(e.what()).find(part), std::string::npos)                \
            << "message: " << e.what() << "\nlacks: " << part;                        \
    }                                                                                 \
  } while (false)

// Raw SQLite access to inspect and tamper with the file behind the store's back.
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
  // First column of every row, as text ("NULL" for NULL).
  std::vector<std::string> Column(const std::string& sql) {
    std::vector<std::string> out;
    sqlite3_stmt* s = nullptr;
    EXPECT_EQ(sqlite3_prepare_v2(db_, sql.c_str(), -1, &s, nullptr), SQLITE_OK) << sql;
    while (sqlite3_step(s) == SQLITE_ROW) {
      const auto* t = reinterpret_cast<const char*>(sqlite3_column_text(s, 0));
      out.push_back(t != nullptr ? t : "NULL");
    }
    sqlite3_finalize(s);
    return out;
  }

 private:
  sqlite3* db_ = nullptr;
};

Measurement Meas(std::string name, double value, double sigma, std::optional<double> lo,
                 std::optional<double> hi, MeasurementOutcome outcome, bool marginal = false) {
  Measurement m;
  m.name = std::move(name);
  m.unit = m.name.ends_with("_hz") ? "Hz" : "ohm";
  m.doc = "doc of " + m.name;
  m.value = value;
  m.sigma = sigma;
  m.limit.lo = lo;
  m.limit.hi = hi;
  m.limit.marginal = 0.5;
  m.outcome = outcome;
  m.marginal = marginal;
  return m;
}

TestRecord MakeRecord(const std::string& serial, const std::string& started_at,
                      Outcome outcome = Outcome::kPass) {
  TestRecord r;
  r.serial = serial;
  r.station_id = "EOL-3";
  r.recipe_id = "pm-motor-a";
  r.recipe_version = 7;
  r.recipe_hash = std::string(64, 'a');
  r.software_version = "0.1.0+g1234567";
  r.started_at = started_at;
  r.finished_at = started_at.substr(0, 17) + "59.999Z";
  r.outcome = outcome;
  if (outcome == Outcome::kFail) r.reasons = {{ReasonCode::kLimit, "winding_r_ohm 1.9 above 1.5"}};
  return r;
}

TestRecord MakeFullRecord(const std::string& serial, const std::string& started_at) {
  TestRecord r = MakeRecord(serial, started_at, Outcome::kFail);
  r.reasons = {{ReasonCode::kLimit, "winding_r_ohm 1.9 above 1.5"},
               {ReasonCode::kMask, "resonance_f_hz marginal"}};
  r.measurements = {
      Meas("resonance_f_hz", 1234.5678901234567, 0.25, 1000.0, 1500.0, MeasurementOutcome::kPass,
           /*marginal=*/true),
      Meas("winding_r_ohm", 1.9, 1.0 / 3.0, std::nullopt, 1.5, MeasurementOutcome::kFail),
      Meas("insulation_r_ohm", 2.5e9, kNaN, 1e8, std::nullopt, MeasurementOutcome::kPass),
      Meas("damping", 0.01, kNaN, std::nullopt, std::nullopt, MeasurementOutcome::kUnset),
  };
  r.conditions.clamp_pressure_bar = 5.1;
  r.conditions.phase_pair = 0;
  r.conditions.excitation_peak_v = 2.0;
  r.conditions.extra = {{"humidity_pct", 41.5}};  // a key of another version: kept
  r.calibration = {{"shunt_ohm", 0.1}, {"date", "2024-04-30"}};
  r.fit = {{"termination", "CONVERGENCE"}, {"iterations", 12}, {"usable", true}};
  Curve z{"impedance",         "ohm", {10.0, 100.0, 1000.0}, {1.5, 1.25, 0.1}, {0.01, 0.5, 2.0},
          {1e-3, kNaN, 1e-300}};
  Curve model{"model", "ohm", {10.0, 100.0}, {1.0 / 7.0, -2.0}, {3e12, 0.0}, {}};
  r.curves = {z, model};
  r.trace = {{"IDLE", 0.0, ""}, {"CLAMP", 12.5, "5.1 bar"}, {"MEASURE", 812.25, "pair 0"}};
  return r;
}

// What a stored curve keeps (db/curve_codec.h): each value to a thousandth of its line's sigma,
// to 1e-6 of itself without a sigma, exactly where float32 cannot (a NaN stays NaN).
void ExpectKept(const std::vector<double>& got, const std::vector<double>& want,
                const std::vector<double>& sigma, const char* what) {
  ASSERT_EQ(got.size(), want.size()) << what;
  for (std::size_t i = 0; i < want.size(); ++i) {
    if (std::isnan(want[i])) {
      EXPECT_TRUE(std::isnan(got[i])) << what << "[" << i << "]";
      continue;
    }
    const double tol = sigma.empty()             ? 1e-6 * std::abs(want[i])
                       : std::isfinite(sigma[i]) ? 1e-3 * sigma[i]
                                                 : 0.0;
    EXPECT_NEAR(got[i], want[i], tol) << what << "[" << i << "]";
  }
}

// NaN-aware element-wise equality.
void ExpectSame(const std::vector<double>& a, const std::vector<double>& b, const char* what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (std::isnan(a[i]))
      EXPECT_TRUE(std::isnan(b[i])) << what << "[" << i << "]";
    else
      EXPECT_EQ(a[i], b[i]) << what << "[" << i << "]";
  }
}

class StoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("eol_store_test_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    path_ = dir_ / "eol.db";
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  std::unique_ptr<Store> Open() { return Store::Open(path_.string()); }

  fs::path dir_;
  fs::path path_;
};

TEST_F(StoreTest, OpenCreatesTheSchemaWithWalAndVersion) {
  auto store = Open();
  EXPECT_EQ(store->path(), path_.string());
  EXPECT_EQ(store->aborted_on_open(), 0);
  RawDb raw(path_);
  EXPECT_EQ(raw.Column("PRAGMA journal_mode"), std::vector<std::string>{"wal"});
  EXPECT_EQ(raw.Column("PRAGMA user_version"),
            std::vector<std::string>{std::to_string(Store::kSchemaVersion)});
  EXPECT_EQ(raw.Column("SELECT name FROM sqlite_schema WHERE type = 'table' ORDER BY name"),
            (std::vector<std::string>{"curves", "measurements", "outbox", "outbox_cursors",
                                      "recipe_audit", "self_checks", "sqlite_sequence", "teardowns",
                                      "tests"}));
  const auto indexes = raw.Column("SELECT name FROM sqlite_schema WHERE type = 'index'");
  for (const char* name : {"tests_serial_started", "tests_started", "measurements_name"})
    EXPECT_NE(std::find(indexes.begin(), indexes.end(), name), indexes.end()) << name;
  // Re-opening a current file migrates nothing and keeps the data.
  TestRecord r = MakeRecord("S1", "2024-05-01T10:00:00.000Z");
  store->Insert(r);
  store.reset();
  store = Open();
  EXPECT_TRUE(store->Test(r.id).has_value());
}

TEST_F(StoreTest, FullRecordRoundTrips) {
  auto store = Open();
  TestRecord in = MakeFullRecord("M-0001", "2024-05-01T10:00:00.000Z");
  in.id = 999;  // whatever an imported record carried: the store assigns its own
  store->Insert(in);
  ASSERT_GT(in.id, 0);
  EXPECT_NE(in.id, 999);
  EXPECT_FALSE(in.retest_of.has_value());

  const std::optional<TestRecord> out = store->Test(in.id);
  ASSERT_TRUE(out.has_value());
  EXPECT_EQ(out->id, in.id);
  EXPECT_EQ(out->serial, in.serial);
  EXPECT_EQ(out->station_id, in.station_id);
  EXPECT_EQ(out->recipe_id, in.recipe_id);
  EXPECT_EQ(out->recipe_version, in.recipe_version);
  EXPECT_EQ(out->recipe_hash, in.recipe_hash);
  EXPECT_EQ(out->software_version, in.software_version);
  EXPECT_EQ(out->started_at, in.started_at);
  EXPECT_EQ(out->finished_at, in.finished_at);
  EXPECT_EQ(out->retest_of, std::nullopt);
  EXPECT_EQ(out->outcome, Outcome::kFail);
  EXPECT_EQ(out->reasons, in.reasons);
  EXPECT_EQ(out->conditions, in.conditions);
  EXPECT_EQ(out->calibration, in.calibration);
  EXPECT_EQ(out->fit, in.fit);

  ASSERT_EQ(out->measurements.size(), in.measurements.size());
  for (std::size_t i = 0; i < in.measurements.size(); ++i) {
    const Measurement& a = in.measurements[i];
    const Measurement& b = out->measurements[i];
    SCOPED_TRACE(a.name);
    EXPECT_EQ(b.name, a.name);
    EXPECT_EQ(b.unit, a.unit);
    EXPECT_EQ(b.doc, a.doc);
    EXPECT_EQ(b.value, a.value);
    ExpectSame({a.sigma}, {b.sigma}, "sigma");
    EXPECT_EQ(b.limit.lo, a.limit.lo);
    EXPECT_EQ(b.limit.hi, a.limit.hi);
    EXPECT_EQ(b.limit.marginal, a.limit.marginal);
    EXPECT_EQ(b.outcome, a.outcome);
    EXPECT_EQ(b.marginal, a.marginal);
  }
  EXPECT_TRUE(std::isnan(out->measurements[2].sigma));

  ASSERT_EQ(out->curves.size(), 2u);
  for (std::size_t i = 0; i < in.curves.size(); ++i) {
    SCOPED_TRACE(in.curves[i].name);
    EXPECT_EQ(out->curves[i].name, in.curves[i].name);
    EXPECT_EQ(out->curves[i].unit, in.curves[i].unit);
    ExpectSame(out->curves[i].freq_hz, in.curves[i].freq_hz, "freq_hz");
    ExpectKept(out->curves[i].re, in.curves[i].re, in.curves[i].sigma, "re");
    ExpectKept(out->curves[i].im, in.curves[i].im, in.curves[i].sigma, "im");
    ExpectSame(out->curves[i].sigma, in.curves[i].sigma, "sigma");
  }

  ASSERT_EQ(out->trace.size(), in.trace.size());
  for (std::size_t i = 0; i < in.trace.size(); ++i) {
    EXPECT_EQ(out->trace[i].state, in.trace[i].state);
    EXPECT_EQ(out->trace[i].t_ms, in.trace[i].t_ms);
    EXPECT_EQ(out->trace[i].detail, in.trace[i].detail);
  }

  // Without curves: everything else, no curves.
  const std::optional<TestRecord> light = store->Test(in.id, /*with_curves=*/false);
  ASSERT_TRUE(light.has_value());
  EXPECT_TRUE(light->curves.empty());
  EXPECT_EQ(light->measurements.size(), 4u);
  EXPECT_FALSE(store->Test(in.id + 1000).has_value());
}

TEST_F(StoreTest, MeasurementsAndCurvesAreQueryableRows) {
  auto store = Open();
  TestRecord r = MakeFullRecord("M-0002", "2024-05-01T10:00:00.000Z");
  store->Insert(r);
  RawDb raw(path_);
  const std::string where = " FROM measurements WHERE test_id = " + std::to_string(r.id);
  EXPECT_EQ(
      raw.Column("SELECT name" + where + " ORDER BY id"),
      (std::vector<std::string>{"resonance_f_hz", "winding_r_ohm", "insulation_r_ohm", "damping"}));
  // NaN sigma and open limits are NULL.
  EXPECT_EQ(raw.Column("SELECT sigma IS NULL" + where + " ORDER BY id"),
            (std::vector<std::string>{"0", "0", "1", "1"}));
  EXPECT_EQ(raw.Column("SELECT sigma = 1.0 / 3.0" + where + " AND name = 'winding_r_ohm'"),
            std::vector<std::string>{"1"});
  EXPECT_EQ(
      raw.Column("SELECT quote(lo) || ',' || quote(hi)" + where + " ORDER BY id"),
      (std::vector<std::string>{"1000.0,1500.0", "NULL,1.5", "100000000.0,NULL", "NULL,NULL"}));
  EXPECT_EQ(raw.Column("SELECT outcome || marginal" + where + " ORDER BY id"),
            (std::vector<std::string>{"PASS1", "FAIL0", "PASS0", "UNSET0"}));
  EXPECT_EQ(raw.Column("SELECT name FROM curves ORDER BY id"),
            (std::vector<std::string>{"impedance", "model"}));
  // The record column holds no curves: they live compressed in their own table.
  EXPECT_EQ(raw.Column("SELECT json_type(record, '$.curves') FROM tests"),
            std::vector<std::string>{"NULL"});
  EXPECT_EQ(raw.Column("SELECT json_extract(record, '$.outcome') FROM tests"),
            std::vector<std::string>{"FAIL"});
}

TEST_F(StoreTest, TestsOfSerialAreNewestFirstAndRetestsLinkToTheFirst) {
  auto store = Open();
  TestRecord first = MakeRecord("M-7", "2024-05-01T10:00:00.000Z", Outcome::kFail);
  TestRecord other = MakeRecord("M-8", "2024-05-01T10:05:00.000Z");
  TestRecord second = MakeRecord("M-7", "2024-05-01T11:00:00.000Z");
  // Imported later but started in between: ordered by started_at, linked to the first row.
  TestRecord between = MakeRecord("M-7", "2024-05-01T10:30:00.000Z", Outcome::kError);
  // Same start as `second`: the later id is newer.
  TestRecord tie = MakeRecord("M-7", "2024-05-01T11:00:00.000Z");
  for (TestRecord* r : {&first, &other, &second, &between, &tie}) store->Insert(*r);

  EXPECT_FALSE(first.retest_of.has_value());
  EXPECT_FALSE(other.retest_of.has_value());
  EXPECT_EQ(second.retest_of, first.id);
  EXPECT_EQ(between.retest_of, first.id);
  EXPECT_EQ(tie.retest_of, first.id);

  const std::vector<TestRecord> tests = store->TestsOfSerial("M-7");
  ASSERT_EQ(tests.size(), 4u);
  EXPECT_EQ(tests[0].id, tie.id);
  EXPECT_EQ(tests[1].id, second.id);
  EXPECT_EQ(tests[2].id, between.id);
  EXPECT_EQ(tests[3].id, first.id);
  EXPECT_EQ(tests[3].outcome, Outcome::kFail);
  EXPECT_EQ(tests[2].retest_of, first.id);
  EXPECT_FALSE(tests[3].retest_of.has_value());

  const std::optional<TestRecord> latest = store->LatestOfSerial("M-7");
  ASSERT_TRUE(latest.has_value());
  EXPECT_EQ(latest->id, tie.id);
  EXPECT_FALSE(store->LatestOfSerial("M-9").has_value());
  EXPECT_TRUE(store->TestsOfSerial("M-9").empty());
}

TEST_F(StoreTest, InsertAllIsOneTransactionAllOrNothing) {
  auto store = Open();
  std::vector<TestRecord> batch = {MakeRecord("B-1", "2024-05-01T10:00:00.000Z"),
                                   MakeRecord("B-1", "2024-05-01T10:01:00.000Z"),
                                   MakeRecord("B-2", "2024-05-01T10:02:00.000Z")};
  store->InsertAll(batch);
  EXPECT_GT(batch[0].id, 0);
  EXPECT_EQ(batch[1].retest_of, batch[0].id);  // linked within the same transaction
  EXPECT_EQ(store->TestsOfSerial("B-1").size(), 2u);

  std::vector<TestRecord> bad = {MakeRecord("B-3", "2024-05-01T10:03:00.000Z"),
                                 MakeRecord("", "2024-05-01T10:04:00.000Z")};  // no serial
  EXPECT_THROW(store->InsertAll(bad), StoreError);
  EXPECT_TRUE(store->TestsOfSerial("B-3").empty());  // rolled back with the bad one
  EXPECT_EQ(bad[0].id, 0);                           // and no id kept that is not in the file
}

TEST_F(StoreTest, CurvesLoadOnlyWhenAsked) {
  auto store = Open();
  TestRecord r = MakeFullRecord("M-1", "2024-05-01T10:00:00.000Z");
  store->Insert(r);
  EXPECT_TRUE(store->TestsOfSerial("M-1").at(0).curves.empty());
  EXPECT_EQ(store->TestsOfSerial("M-1", /*with_curves=*/true).at(0).curves.size(), 2u);
  EXPECT_TRUE(store->Tests({}).at(0).curves.empty());
  TestQuery q;
  q.with_curves = true;
  EXPECT_EQ(store->Tests(q).at(0).curves.size(), 2u);
  EXPECT_EQ(store->LatestOfSerial("M-1")->curves.size(), 2u);
}

TEST_F(StoreTest, RunningTestIsHiddenAndBecomesAbortedAfterACrash) {
  TestRecord r = MakeRecord("M-42", "2024-05-01T10:00:00.000Z");
  r.finished_at.clear();
  {
    auto store = Open();
    store->BeginTest(r);
    ASSERT_GT(r.id, 0);
    EXPECT_FALSE(r.retest_of.has_value());
    EXPECT_FALSE(store->Test(r.id).has_value());
    EXPECT_TRUE(store->TestsOfSerial("M-42").empty());
    EXPECT_FALSE(store->LatestOfSerial("M-42").has_value());
    EXPECT_TRUE(store->Tests({}).empty());
    // The station dies here: the Store goes away without FinishTest.
  }
  auto store = Open();
  EXPECT_EQ(store->aborted_on_open(), 1);
  const std::optional<TestRecord> aborted = store->Test(r.id);
  ASSERT_TRUE(aborted.has_value());
  EXPECT_EQ(aborted->outcome, Outcome::kAborted);
  EXPECT_EQ(aborted->serial, "M-42");
  EXPECT_EQ(aborted->recipe_hash, r.recipe_hash);
  const analysis::Reason interrupted{ReasonCode::kAborted,
                                     "interrupted: station stopped before the test finished"};
  EXPECT_EQ(aborted->reasons, std::vector<analysis::Reason>{interrupted});
  EXPECT_TRUE(std::regex_match(aborted->finished_at,
                               std::regex(R"(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z)")))
      << aborted->finished_at;
  EXPECT_TRUE(aborted->measurements.empty());
  EXPECT_EQ(store->TestsOfSerial("M-42").size(), 1u);

  // Late: the test cannot be finished any more.
  r.finished_at = "2024-05-01T10:01:00.000Z";
  EXPECT_STORE_ERROR(store->FinishTest(r), "ABORTED", "not RUNNING", path_.string());

  // A retest links to the aborted first attempt.
  TestRecord again = MakeRecord("M-42", "2024-05-01T10:10:00.000Z");
  store->Insert(again);
  EXPECT_EQ(again.retest_of, r.id);

  store.reset();
  EXPECT_EQ(Open()->aborted_on_open(), 0);
}

TEST_F(StoreTest, ReaderConnectionNeverAbortsARunningTest) {
  auto writer = Open();
  TestRecord r = MakeRecord("M-7", "2024-05-01T10:00:00.000Z");
  r.finished_at.clear();
  writer->BeginTest(r);
  {
    auto reader = Store::Open(path_.string(), Store::Role::kReader);
    EXPECT_EQ(reader->aborted_on_open(), 0);
    EXPECT_TRUE(reader->TestsOfSerial("M-7").empty());
  }
  r.finished_at = "2024-05-01T10:00:05.000Z";
  writer->FinishTest(r);  // still RUNNING: the reader did not touch it
  auto reader = Store::Open(path_.string(), Store::Role::kReader);
  ASSERT_EQ(reader->TestsOfSerial("M-7").size(), 1u);
  EXPECT_EQ(reader->TestsOfSerial("M-7").front().outcome, r.outcome);
}

TEST_F(StoreTest, BeginThenFinishWritesTheVerdict) {
  auto store = Open();
  TestRecord r = MakeFullRecord("M-5", "2024-05-01T10:00:00.000Z");
  store->BeginTest(r);
  store->FinishTest(r);
  const std::optional<TestRecord> out = store->Test(r.id);
  ASSERT_TRUE(out.has_value());
  EXPECT_EQ(out->outcome, Outcome::kFail);
  EXPECT_EQ(out->measurements.size(), 4u);
  EXPECT_EQ(out->curves.size(), 2u);
}

TEST_F(StoreTest, FinishingTwiceThrowsAndKeepsTheFirstVerdict) {
  auto store = Open();
  TestRecord r = MakeRecord("M-6", "2024-05-01T10:00:00.000Z", Outcome::kPass);
  r.measurements = {Meas("winding_r_ohm", 1.2, 0.01, 1.0, 1.5, MeasurementOutcome::kPass)};
  store->BeginTest(r);
  store->FinishTest(r);
  r.outcome = Outcome::kFail;
  EXPECT_STORE_ERROR(store->FinishTest(r), "test " + std::to_string(r.id), "PASS", "not RUNNING",
                     path_.string());
  EXPECT_EQ(store->Test(r.id)->outcome, Outcome::kPass);
  // The failed attempt wrote nothing: still one measurement row.
  RawDb raw(path_);
  EXPECT_EQ(raw.Column("SELECT count(*) FROM measurements"), std::vector<std::string>{"1"});
}

TEST_F(StoreTest, FinishWithoutBeginThrows) {
  auto store = Open();
  TestRecord r = MakeRecord("M-6", "2024-05-01T10:00:00.000Z");
  r.id = 12345;
  EXPECT_STORE_ERROR(store->FinishTest(r), "finish test 12345", "no such test");
  r.id = 0;
  EXPECT_STORE_ERROR(store->FinishTest(r), "finish test 0", "BeginTest");
}

TEST_F(StoreTest, IncompleteRecordsAreRefusedNamingTheField) {
  auto store = Open();
  TestRecord no_serial = MakeRecord("", "2024-05-01T10:00:00.000Z");
  EXPECT_STORE_ERROR(store->Insert(no_serial), "record.serial");
  EXPECT_EQ(no_serial.id, 0);
  TestRecord unfinished = MakeRecord("M-1", "2024-05-01T10:00:00.000Z");
  unfinished.finished_at.clear();
  EXPECT_STORE_ERROR(store->Insert(unfinished), "record.finished_at");
  // Insert is one transaction: the refused record left no RUNNING row behind.
  EXPECT_EQ(unfinished.id, 0);
  store.reset();
  EXPECT_EQ(Open()->aborted_on_open(), 0);
}

TEST_F(StoreTest, NewerSchemaVersionFailsToOpen) {
  Open().reset();
  {
    RawDb raw(path_);
    raw.Exec("PRAGMA user_version = " + std::to_string(Store::kSchemaVersion + 1));
  }
  EXPECT_STORE_ERROR(Open(), path_.string(),
                     "schema version " + std::to_string(Store::kSchemaVersion + 1),
                     "newer than this software knows");
}

TEST_F(StoreTest, ForeignDatabaseIsRefused) {
  {
    RawDb raw(path_);
    raw.Exec("CREATE TABLE inventory (part TEXT)");
  }
  EXPECT_STORE_ERROR(Open(), path_.string(), "not an EOL test store");
}

TEST_F(StoreTest, FileThatIsNotADatabaseFailsNamingThePath) {
  std::ofstream(path_) << "serial,outcome\nM-1,PASS\n" << std::string(4096, 'x');
  EXPECT_STORE_ERROR(Open(), path_.string(), "open", "not a database");
}

TEST_F(StoreTest, UnwritablePathFailsNamingThePath) {
  // A directory that does not exist (a read-only file does not stop root, who runs CI).
  const fs::path missing = dir_ / "no_such_dir" / "eol.db";
  // The writer's lock beside the file is the first thing that cannot be created.
  EXPECT_STORE_ERROR(Store::Open(missing.string()), "'" + missing.string() + "'", "open",
                     "No such file or directory");
  // A directory where the file should be.
  EXPECT_STORE_ERROR(Store::Open(dir_.string()), "'" + dir_.string() + "'", "open");
}

TEST_F(StoreTest, ValuesAreBoundNotSpliced) {
  auto store = Open();
  const std::vector<std::string> serials = {"x'); DROP TABLE tests;--", "O'Brien \"q\" %_*",
                                            "M\xC3\xBCller-\xE2\x82\xAC", "x"};
  std::vector<std::int64_t> ids;
  for (const std::string& serial : serials) {
    TestRecord r = MakeRecord(serial, "2024-05-01T10:00:00.000Z");
    r.station_id = serial;
    r.reasons = {{ReasonCode::kLimit, serial}};
    store->Insert(r);
    ids.push_back(r.id);
  }
  for (std::size_t i = 0; i < serials.size(); ++i) {
    const std::vector<TestRecord> found = store->TestsOfSerial(serials[i]);
    ASSERT_EQ(found.size(), 1u) << serials[i];
    EXPECT_EQ(found[0].id, ids[i]);
    EXPECT_EQ(found[0].serial, serials[i]);
    EXPECT_EQ(found[0].station_id, serials[i]);
    EXPECT_EQ(found[0].reasons, (std::vector<analysis::Reason>{{ReasonCode::kLimit, serials[i]}}));
    TestQuery q;
    q.serial = serials[i];
    EXPECT_EQ(store->Tests(q).size(), 1u) << serials[i];
  }
  // LIKE wildcards are plain characters.
  EXPECT_TRUE(store->TestsOfSerial("%").empty());
  EXPECT_EQ(store->Tests({}).size(), serials.size());
  // The tests table survived.
  TestRecord after = MakeRecord("after", "2024-05-01T11:00:00.000Z");
  store->Insert(after);
  EXPECT_TRUE(store->Test(after.id).has_value());
}

TEST_F(StoreTest, TestsFiltersByOutcomeTimeSerialAndLimit) {
  auto store = Open();
  struct Row {
    const char* serial;
    const char* started_at;
    Outcome outcome;
  };
  const Row rows[] = {
      {"A", "2024-05-01T08:00:00.000Z", Outcome::kPass},
      {"B", "2024-05-01T09:00:00.000Z", Outcome::kFail},
      {"C", "2024-05-01T23:59:59.999Z", Outcome::kPass},
      {"A", "2024-05-02T00:00:00.000Z", Outcome::kFail},
      {"D", "2024-05-02T12:00:00.000Z", Outcome::kError},
      {"E", "2024-05-03T12:00:00.000Z", Outcome::kAborted},
  };
  for (const Row& row : rows) {
    TestRecord r = MakeRecord(row.serial, row.started_at, row.outcome);
    store->Insert(r);
  }
  TestRecord running = MakeRecord("A", "2024-05-02T01:00:00.000Z");
  store->BeginTest(running);

  auto serials = [&](const TestQuery& q) {
    std::vector<std::string> out;
    for (const TestRecord& r : store->Tests(q)) out.push_back(r.serial + "@" + r.started_at);
    return out;
  };
  using V = std::vector<std::string>;

  // No filter: everything but the running test, newest first.
  EXPECT_EQ(store->Tests({}).size(), 6u);
  EXPECT_EQ(store->Tests({}).front().serial, "E");

  TestQuery fails;
  fails.outcome = Outcome::kFail;
  EXPECT_EQ(serials(fails), (V{"A@2024-05-02T00:00:00.000Z", "B@2024-05-01T09:00:00.000Z"}));

  TestQuery aborted;
  aborted.outcome = Outcome::kAborted;
  EXPECT_EQ(serials(aborted), V{"E@2024-05-03T12:00:00.000Z"});

  // from is inclusive, to exclusive; a bare date is midnight.
  TestQuery day;
  day.from = "2024-05-01";
  day.to = "2024-05-02";
  EXPECT_EQ(serials(day), (V{"C@2024-05-01T23:59:59.999Z", "B@2024-05-01T09:00:00.000Z",
                             "A@2024-05-01T08:00:00.000Z"}));
  TestQuery exact;
  exact.from = "2024-05-01T09:00:00.000Z";
  exact.to = "2024-05-02T12:00:00.000Z";
  EXPECT_EQ(serials(exact), (V{"A@2024-05-02T00:00:00.000Z", "C@2024-05-01T23:59:59.999Z",
                               "B@2024-05-01T09:00:00.000Z"}));

  TestQuery since;
  since.from = "2024-05-02T00:00:00.000Z";
  since.outcome = Outcome::kFail;
  EXPECT_EQ(serials(since), V{"A@2024-05-02T00:00:00.000Z"});

  TestQuery serial_a;
  serial_a.serial = "A";
  EXPECT_EQ(serials(serial_a), (V{"A@2024-05-02T00:00:00.000Z", "A@2024-05-01T08:00:00.000Z"}));

  TestQuery two;
  two.limit = 2;
  EXPECT_EQ(serials(two), (V{"E@2024-05-03T12:00:00.000Z", "D@2024-05-02T12:00:00.000Z"}));
  TestQuery zero;
  zero.limit = 0;  // clamped to 1
  EXPECT_EQ(store->Tests(zero).size(), 1u);
  TestQuery negative;
  negative.limit = -5;
  EXPECT_EQ(store->Tests(negative).size(), 1u);
  TestQuery huge;
  huge.limit = 1 << 30;  // clamped to 10000
  EXPECT_EQ(store->Tests(huge).size(), 6u);

  TestQuery none;
  none.from = "2025-01-01";
  EXPECT_TRUE(store->Tests(none).empty());
}

TEST_F(StoreTest, TwoStoresOnOneFileSeeEachOthersCommits) {
  auto writer = Open();
  auto reader = Store::Open(path_.string(), Store::Role::kReader);  // one writer per file
  TestRecord r = MakeRecord("M-1", "2024-05-01T10:00:00.000Z");
  writer->Insert(r);
  EXPECT_TRUE(reader->Test(r.id).has_value());
  TestRecord retest = MakeRecord("M-1", "2024-05-01T11:00:00.000Z");
  reader->Insert(retest);
  EXPECT_EQ(retest.retest_of, r.id);
  EXPECT_EQ(writer->TestsOfSerial("M-1").size(), 2u);
}

}  // namespace
}  // namespace eol::db

namespace eol::db {
namespace {

class StoreMigrationTest : public ::testing::Test {
 protected:
  void SetUp() override { fs::create_directories(dir_); }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_ = fs::temp_directory_path() / ("eol-migrate-" + std::to_string(getpid()));
};

TEST_F(StoreMigrationTest, VersionOneFileMigratesToTwoKeepingItsTests) {
  const fs::path path = dir_ / "v1.sqlite";
  {
    RawDb raw(path);
    raw.Exec(schema::kSchemaV1);
    raw.Exec("PRAGMA application_id = " + std::to_string(schema::kApplicationId) +
             "; PRAGMA user_version = 1");
    raw.Exec(
        "INSERT INTO tests (serial, station_id, recipe_id, recipe_version, recipe_hash, "
        "software_version, started_at, finished_at, outcome, reasons) VALUES ('OLD-1', 's', "
        "'r', 1, 'h', 'v', '2025-01-01T00:00:00.000Z', '2025-01-01T00:00:01.000Z', 'PASS', "
        "'[]')");
  }
  auto store = Store::Open(path.string());
  RawDb raw(path);
  EXPECT_EQ(raw.Column("PRAGMA user_version"),
            std::vector<std::string>{std::to_string(Store::kSchemaVersion)});
  EXPECT_EQ(store->TestsOfSerial("OLD-1").size(), 1u);
  EXPECT_TRUE(store->AuditLog().empty());
}

// Before reasons had codes, the reasons column and the record JSON held plain strings; such
// rows read back with the code "legacy" and their text unchanged.
TEST_F(StoreMigrationTest, PlainStringReasonsOfAnOldFileReadAsLegacy) {
  const fs::path path = dir_ / "old-reasons.sqlite";
  {
    RawDb raw(path);
    raw.Exec(schema::kSchemaV1);
    raw.Exec("PRAGMA application_id = " + std::to_string(schema::kApplicationId) +
             "; PRAGMA user_version = 1");
    raw.Exec(
        "INSERT INTO tests (serial, station_id, recipe_id, recipe_version, recipe_hash, "
        "software_version, started_at, finished_at, outcome, reasons, record) VALUES ('OLD-R', "
        "'s', 'r', 1, 'h', 'v', '2025-01-01T00:00:00.000Z', '2025-01-01T00:00:01.000Z', 'FAIL', "
        "'[\"resonance_f_hz = 352 Hz below lower limit 370\", \"mask m: worst line\"]', "
        "'{\"serial\": \"OLD-R\", \"recipe\": {\"id\": \"r\"}, \"outcome\": \"FAIL\", "
        "\"reasons\": [\"resonance_f_hz = 352 Hz below lower limit 370\"]}')");
  }
  auto store = Store::Open(path.string());
  const auto tests = store->TestsOfSerial("OLD-R");
  ASSERT_EQ(tests.size(), 1u);
  EXPECT_EQ(tests[0].outcome, Outcome::kFail);
  const std::vector<analysis::Reason> want = {
      {ReasonCode::kLegacy, "resonance_f_hz = 352 Hz below lower limit 370"},
      {ReasonCode::kLegacy, "mask m: worst line"}};
  EXPECT_EQ(tests[0].reasons, want);
  // The record JSON alone (an export of that time) reads the same way.
  const TestRecord from_json = nlohmann::json::parse(
                                   R"({"serial": "OLD-R", "recipe": {"id": "r"}, "outcome": "FAIL",
                                       "reasons": ["mask m: worst line"]})")
                                   .get<TestRecord>();
  EXPECT_EQ(from_json.reasons, std::vector<analysis::Reason>{want[1]});
  // New records are written as {code, text}.
  EXPECT_EQ(nlohmann::json(want[0]).dump(),
            R"({"code":"legacy","text":"resonance_f_hz = 352 Hz below lower limit 370"})");
  try {
    (void)nlohmann::json::parse(R"({"code": "nope", "text": "x"})").get<analysis::Reason>();
    FAIL() << "an unknown reason code was accepted";
  } catch (const nlohmann::json::exception& e) {
    EXPECT_NE(std::string(e.what()).find("reasons: unknown code 'nope'"), std::string::npos)
        << e.what();
  }
}

TEST_F(StoreMigrationTest, AuditLogRoundTripsNewestFirst) {
  auto store = Store::Open((dir_ / "a.sqlite").string());
  RecipeAudit a{"2026-11-22T05:00:00.000Z",
                "qe-anna",
                "engineer",
                "pmsm-10pole",
                1,
                2,
                std::string(64, 'a'),
                std::string(64, 'b'),
                "/etc/eol/recipe.json"};
  RecipeAudit b = a;
  b.at = "2026-11-22T06:00:00.000Z";
  b.old_version = 2;
  b.new_version = 3;
  store->AppendAudit(a);
  store->AppendAudit(b);
  const auto log = store->AuditLog();
  ASSERT_EQ(log.size(), 2u);
  EXPECT_EQ(log[0].new_version, 3);
  EXPECT_EQ(log[1].who, "qe-anna");
  EXPECT_EQ(log[1].old_version, 1);
  EXPECT_EQ(log[1].old_hash, std::string(64, 'a'));
}

// One station per database: a second writer is refused before it recovers (aborts) the
// first one's running test; readers are not affected.
TEST_F(StoreTest, ASecondWriterIsRefusedWhileTheFirstIsOpen) {
  auto first = Open();
  TestRecord running;
  running.serial = "RUN-1";
  running.station_id = "s1";
  running.recipe_id = "r";
  running.recipe_hash = std::string(64, 'a');
  running.software_version = "t";
  running.started_at = "2026-11-20T08:00:00.000Z";
  first->BeginTest(running);
  try {
    Store::Open(path_.string());
    ADD_FAILURE() << "a second writer opened the store";
  } catch (const StoreError& e) {
    EXPECT_EQ(std::string(e.what()), "store '" + path_.string() +
                                         "': lock: another station holds " + path_.string() +
                                         ".lock (one station per database; stop the other first)");
  }
  EXPECT_NO_THROW(Store::Open(path_.string(), Store::Role::kReader));
  first.reset();
  auto second = Open();
  EXPECT_EQ(second->aborted_on_open(), 1) << "the lock is released with the first store";
}

}  // namespace
}  // namespace eol::db
