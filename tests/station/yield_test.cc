// Yield (station/reports/yield.h): the figures of hand-made tests worked out by hand below, through
// ComputeYield, `eol stats --yield` on a real store and GET /api/yield (real HTTP on
// 127.0.0.1); the Pareto chart; retest marking (the attempt each stored test knows).
#include "station/reports/yield.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <tuple>

#include "../support/child_process.h"
#include "db/store.h"
#include "station/daemon/http_api.h"
#include "station/daemon/status_board.h"
#include "tests/support/eol_cli.h"

// After Eigen: <resolv.h> (through httplib) defines _res, a parameter name in Eigen.
#include <httplib.h>

namespace eol {
namespace {

using namespace std::chrono_literals;
using analysis::Outcome;
using analysis::ReasonCode;

const std::string kHashA(64, 'a');
const std::string kHashB(64, 'b');

// One test of the scenario: serial, UTC start, outcome, decisive reason (none for PASS and
// for the ERROR without a reason), recipe B or A.
struct Spec {
  std::string serial;
  std::string at;  // "2026-11-20T07:00"
  Outcome outcome;
  std::optional<ReasonCode> reason;
  bool recipe_b = false;
};

// The scenario (times UTC; shifts A 06:00, B 14:00, C 22:00):
//   U1 PASS (A); U2 FAIL, FAIL (A); U3 ERROR, PASS (A); U4 ERROR (B); U5 FAIL (B), PASS (C, 23:30);
//   U6 ABORTED (02:00 on the 21st: C of the 20th); U0 FAIL (03:00 on the 21st; its first test
//   on the 19th, before the window: carried over); U7 PASS, U8 ERROR without a reason (A of
//   the 21st, recipe B).
const std::vector<Spec> kScenario = {
    {"U1", "2026-11-20T07:00", Outcome::kPass, {}},
    {"U2", "2026-11-20T07:10", Outcome::kFail, ReasonCode::kLimit},
    {"U3", "2026-11-20T07:20", Outcome::kError, ReasonCode::kInterlock},
    {"U2", "2026-11-20T07:30", Outcome::kFail, ReasonCode::kLimit},
    {"U3", "2026-11-20T07:40", Outcome::kPass, {}},
    {"U4", "2026-11-20T15:00", Outcome::kError, ReasonCode::kFixture},
    {"U5", "2026-11-20T15:10", Outcome::kFail, ReasonCode::kMask},
    {"U5", "2026-11-20T23:30", Outcome::kPass, {}},
    {"U6", "2026-11-21T02:00", Outcome::kAborted, ReasonCode::kAborted},
    {"U0", "2026-11-21T03:00", Outcome::kFail, ReasonCode::kLimit},
    {"U7", "2026-11-21T06:30", Outcome::kPass, {}, true},
    {"U8", "2026-11-21T07:00", Outcome::kError, {}, true},
};

db::OutcomeRow Row(const Spec& s, std::int64_t id, std::optional<std::int64_t> retest_of) {
  db::OutcomeRow r;
  r.test_id = id;
  r.serial = s.serial;
  r.started_at = s.at + ":00.000Z";
  r.outcome = s.outcome;
  r.retest_of = retest_of;
  r.recipe_id = s.recipe_b ? "other" : "pmsm-10pole";
  r.recipe_version = s.recipe_b ? 2 : 1;
  r.recipe_hash = s.recipe_b ? kHashB : kHashA;
  if (s.reason) r.reasons = {{*s.reason, "why"}};
  return r;
}

// The scenario as the store would give it: retest_of is the serial's first test id (U0's is
// test 99, before the window).
std::vector<db::OutcomeRow> Rows() {
  std::vector<db::OutcomeRow> rows;
  std::map<std::string, std::int64_t> first = {{"U0", 99}};
  std::int64_t id = 1;
  for (const Spec& s : kScenario) {
    const auto f = first.find(s.serial);
    rows.push_back(Row(s, id, f == first.end() ? std::nullopt : std::optional(f->second)));
    first.emplace(s.serial, id);
    ++id;
  }
  return rows;
}

const nlohmann::json& Group(const nlohmann::json& report, const std::string& key) {
  for (const auto& g : report.at("groups"))
    if (g.at("key") == key) return g;
  throw std::runtime_error("no group " + key + " in " + report.dump());
}

// The whole window, worked out by hand:
//   8 units (U1..U8; U0 was first tested before the window);
//   first tests PASS: U1, U7 -> first pass 2/8 = 0.25;
//   first PASS/FAIL verdicts: U1 PASS, U2 FAIL, U3 PASS (after its ERROR), U5 FAIL, U7 PASS;
//     U4, U6, U8 have none -> 3/5 = 0.6;
//   last tests: PASS U1 U3 U5 U7 (4), FAIL U2 (1), open U4 U6 U8 (3) -> final 4/8 = 0.5;
//   retested U2 U3 U5 (3); their tests 1+2+2+1+2+1+1+1 = 11 -> 11/8 = 1.375 per unit;
//   12 tests: PASS 4, FAIL 4, ERROR 3, ABORTED 1; 1 carried over (U0);
//   Pareto of the 8 non-PASS tests: limit 3 (U2 twice, U0: 2 units; 3/8), then one each,
//     by code: aborted, fixture, interlock, mask, none (cumulative 4/8 ... 8/8).
void ExpectTotal(const nlohmann::json& t) {
  EXPECT_EQ(t.at("units"), 8);
  EXPECT_EQ(t.at("first_pass"), 2);
  EXPECT_DOUBLE_EQ(t.at("first_pass_yield").get<double>(), 0.25);
  EXPECT_EQ(t.at("first_verdict_units"), 5);
  EXPECT_EQ(t.at("first_verdict_pass"), 3);
  EXPECT_DOUBLE_EQ(t.at("first_verdict_yield").get<double>(), 0.6);
  EXPECT_EQ(t.at("final_pass"), 4);
  EXPECT_EQ(t.at("final_fail"), 1);
  EXPECT_EQ(t.at("final_open"), 3);
  EXPECT_DOUBLE_EQ(t.at("final_yield").get<double>(), 0.5);
  EXPECT_EQ(t.at("retested_units"), 3);
  EXPECT_EQ(t.at("unit_tests"), 11);
  EXPECT_DOUBLE_EQ(t.at("tests_per_unit").get<double>(), 1.375);
  EXPECT_EQ(t.at("tests"), 12);
  EXPECT_EQ(t.at("carried_over_tests"), 1);
  EXPECT_EQ(t.at("outcomes"),
            (nlohmann::json{{"PASS", 4}, {"FAIL", 4}, {"ERROR", 3}, {"ABORTED", 1}}));
  const nlohmann::json& p = t.at("pareto");
  ASSERT_EQ(p.size(), 6u) << p.dump();
  const std::vector<std::string> codes = {"limit",     "aborted", "fixture",
                                          "interlock", "mask",    "none"};
  for (std::size_t i = 0; i < codes.size(); ++i) EXPECT_EQ(p[i].at("code"), codes[i]) << i;
  EXPECT_EQ(p[0].at("tests"), 3);
  EXPECT_EQ(p[0].at("units"), 2);
  EXPECT_DOUBLE_EQ(p[0].at("share").get<double>(), 3.0 / 8.0);
  EXPECT_DOUBLE_EQ(p[1].at("cumulative").get<double>(), 4.0 / 8.0);
  EXPECT_DOUBLE_EQ(p[4].at("cumulative").get<double>(), 7.0 / 8.0);
  EXPECT_DOUBLE_EQ(p[5].at("cumulative").get<double>(), 1.0);
}

// By shift (UTC):
//   2026-11-20 A: tests 1-5; units U1 U2 U3; first pass U1; final PASS U1 U3, FAIL U2;
//     retested U2 U3; Pareto limit 2 tests of 1 unit (2/3), interlock 1.
//   2026-11-20 B: tests 6, 7; units U4 U5; final PASS U5 (its retest ran in C: the unit stays
//     in the group of its first test), open U4.
//   2026-11-20 C: tests 8 (U5), 9 (U6, 02:00 on the 21st), 10 (U0, carried over); unit U6.
//   2026-11-21 A: tests 11, 12; units U7 U8; Pareto "none" 1.
void ExpectShifts(const nlohmann::json& report) {
  ASSERT_EQ(report.at("groups").size(), 4u) << report.dump();
  const std::vector<std::string> keys = {"2026-11-20 A", "2026-11-20 B", "2026-11-20 C",
                                         "2026-11-21 A"};
  for (std::size_t i = 0; i < keys.size(); ++i) EXPECT_EQ(report["groups"][i].at("key"), keys[i]);
  const nlohmann::json& a = Group(report, "2026-11-20 A");
  EXPECT_EQ(a.at("units"), 3);
  EXPECT_EQ(a.at("tests"), 5);
  EXPECT_EQ(a.at("first_pass"), 1);
  EXPECT_EQ(a.at("final_pass"), 2);
  EXPECT_EQ(a.at("final_fail"), 1);
  EXPECT_EQ(a.at("retested_units"), 2);
  ASSERT_EQ(a.at("pareto").size(), 2u);
  EXPECT_EQ(a["pareto"][0].at("code"), "limit");
  EXPECT_EQ(a["pareto"][0].at("tests"), 2);
  EXPECT_EQ(a["pareto"][0].at("units"), 1);
  EXPECT_DOUBLE_EQ(a["pareto"][0].at("share").get<double>(), 2.0 / 3.0);
  const nlohmann::json& b = Group(report, "2026-11-20 B");
  EXPECT_EQ(b.at("units"), 2);
  EXPECT_EQ(b.at("tests"), 2);
  EXPECT_EQ(b.at("final_pass"), 1);
  EXPECT_EQ(b.at("final_open"), 1);
  EXPECT_DOUBLE_EQ(b.at("first_pass_yield").get<double>(), 0.0);
  const nlohmann::json& c = Group(report, "2026-11-20 C");
  EXPECT_EQ(c.at("units"), 1);
  EXPECT_EQ(c.at("tests"), 3);
  EXPECT_EQ(c.at("carried_over_tests"), 1);
  EXPECT_EQ(c.at("final_open"), 1);
  const nlohmann::json& next = Group(report, "2026-11-21 A");
  EXPECT_EQ(next.at("units"), 2);
  EXPECT_DOUBLE_EQ(next.at("first_pass_yield").get<double>(), 0.5);
  ASSERT_EQ(next.at("pareto").size(), 1u);
  EXPECT_EQ(next["pareto"][0].at("code"), "none");
}

nlohmann::json Report(station::YieldGrouping by, std::optional<int> offset = 0) {
  station::YieldOptions o;
  o.by = by;
  o.utc_offset_min = offset;
  const station::YieldFigures f = station::ComputeYield(Rows(), o);
  nlohmann::json groups = nlohmann::json::array();
  for (const auto& g : f.groups) groups.push_back(station::ToJson(g));
  return {{"total", station::ToJson(f.total)}, {"groups", groups}};
}

TEST(Yield, TotalOfTheHandMadeTests) {
  const nlohmann::json r = Report(station::YieldGrouping::kAll);
  ExpectTotal(r.at("total"));
  EXPECT_TRUE(r.at("groups").empty());
}

TEST(Yield, PerShiftTheUnitStaysWithItsFirstTest) {
  const nlohmann::json r = Report(station::YieldGrouping::kShift);
  ExpectShifts(r);
  ExpectTotal(r.at("total"));  // grouping changes no total
}

// At UTC+01:00 U5's retest (23:30Z) falls on the 21st: day 20 has tests 1-7 and units U1..U5
// with final PASS U1 U3 U5 (U5's PASS on the 21st counts for its unit on the 20th); day 21
// has tests 8-12 and units U6 U7 U8.
TEST(Yield, PerDayInLocalTime) {
  const nlohmann::json r = Report(station::YieldGrouping::kDay, 60);
  ASSERT_EQ(r.at("groups").size(), 2u) << r.dump();
  const nlohmann::json& d20 = Group(r, "2026-11-20");
  EXPECT_EQ(d20.at("tests"), 7);
  EXPECT_EQ(d20.at("units"), 5);
  EXPECT_EQ(d20.at("final_pass"), 3);
  EXPECT_DOUBLE_EQ(d20.at("final_yield").get<double>(), 0.6);
  const nlohmann::json& d21 = Group(r, "2026-11-21");
  EXPECT_EQ(d21.at("tests"), 5);
  EXPECT_EQ(d21.at("units"), 3);
  EXPECT_EQ(d21.at("carried_over_tests"), 1);
  // In UTC the 23:30 retest stays on the 20th.
  EXPECT_EQ(Group(Report(station::YieldGrouping::kDay, 0), "2026-11-20").at("tests"), 8);
}

TEST(Yield, PerRecipe) {
  const nlohmann::json r = Report(station::YieldGrouping::kRecipe);
  ASSERT_EQ(r.at("groups").size(), 2u);
  const nlohmann::json& a = Group(r, "pmsm-10pole v1 (aaaaaaaaaaaa)");
  EXPECT_EQ(a.at("tests"), 10);
  EXPECT_EQ(a.at("units"), 6);
  EXPECT_EQ(a.at("carried_over_tests"), 1);
  const nlohmann::json& b = Group(r, "other v2 (bbbbbbbbbbbb)");
  EXPECT_EQ(b.at("tests"), 2);
  EXPECT_EQ(b.at("units"), 2);
  EXPECT_DOUBLE_EQ(b.at("first_pass_yield").get<double>(), 0.5);
}

TEST(Yield, NothingToDivideIsNull) {
  const station::YieldFigures f = station::ComputeYield({}, {});
  const nlohmann::json t = station::ToJson(f.total);
  EXPECT_EQ(t.at("units"), 0);
  EXPECT_TRUE(t.at("first_pass_yield").is_null());
  EXPECT_TRUE(t.at("final_yield").is_null());
  EXPECT_TRUE(t.at("pareto").empty());
  EXPECT_THROW(station::ParetoChart(t, "x"), std::invalid_argument);
}

TEST(Yield, ShiftsBeforeTheFirstStartBelongToTheDayBefore) {
  std::vector<station::ShiftStart> shifts;
  std::string why;
  ASSERT_TRUE(station::ParseShifts("night=20:00,day=08:00", &shifts, &why)) << why;
  EXPECT_EQ(station::ShiftsText(shifts), "day=08:00,night=20:00");
  station::YieldOptions o;
  o.by = station::YieldGrouping::kShift;
  o.shifts = shifts;
  o.utc_offset_min = 0;
  db::OutcomeRow r = Row({"M1", "2026-12-01T05:00", Outcome::kPass, {}}, 1, std::nullopt);
  const station::YieldFigures f = station::ComputeYield({r}, o);
  ASSERT_EQ(f.groups.size(), 1u);
  EXPECT_EQ(f.groups[0].key, "2026-11-30 night");
  r.started_at = "yesterday";
  EXPECT_THROW(station::ComputeYield({r}, o), std::invalid_argument);
}

TEST(Yield, BadShiftsAreNamed) {
  std::vector<station::ShiftStart> shifts;
  for (const std::string bad : {"", "A", "A=25:00", "A=6:00", "A=06:00,A=07:00", "A=06:00,B=06:00",
                                "A B=06:00", "A=06:00,"}) {
    std::string why;
    EXPECT_FALSE(station::ParseShifts(bad, &shifts, &why)) << bad;
    EXPECT_EQ(why.rfind("'", 0), 0u) << bad << ": " << why;  // it quotes the bad part
  }
}

TEST(Yield, ParetoChartNamesEveryCodeWithItsCounts) {
  const nlohmann::json r = Report(station::YieldGrouping::kAll);
  const std::string svg =
      io::RenderChartSvg(station::ParetoChart(r.at("total"), "Pareto of reasons"));
  for (const std::string word :
       {"1 limit: 3 tests, 2 units", "6 none: 1 tests, 1 units", "cumulative %",
        "8 non-PASS of 12 tests, each under its decisive reason"})
    EXPECT_NE(svg.find(word), std::string::npos) << word;
}

// ---- The store, the command and the API ----

db::TestRecord Record(const Spec& s) {
  db::TestRecord r;
  r.serial = s.serial;
  r.station_id = "s1";
  r.recipe_id = s.recipe_b ? "other" : "pmsm-10pole";
  r.recipe_version = s.recipe_b ? 2 : 1;
  r.recipe_hash = s.recipe_b ? kHashB : kHashA;
  r.software_version = "test";
  r.started_at = s.at + ":00.000Z";
  r.finished_at = s.at + ":30.000Z";
  r.outcome = s.outcome;
  r.max_tests = 3;
  if (s.reason) r.reasons = {{*s.reason, "why"}};
  return r;
}

class YieldStore : public ::testing::Test {
 protected:
  void SetUp() override {
    auto store = db::Store::Open(db_);
    // U0's first test, on the 19th (before the window), and a master's self-check (never
    // production yield), then the scenario.
    db::TestRecord first = Record({"U0", "2026-11-19T10:00", Outcome::kFail, ReasonCode::kLimit});
    store->Insert(first);
    db::TestRecord master = Record({"MASTER", "2026-11-20T08:00", Outcome::kFail, {}});
    master.kind = db::RecordKind::kSelfCheck;
    master.self_check = {{"master", "good"}, {"passed", false}, {"detail", ""}};
    store->Insert(master);
    for (const Spec& s : kScenario) {
      db::TestRecord r = Record(s);
      store->Insert(r);
    }
  }

  eol::testing::TempDir dir_;
  std::string db_ = dir_ / "yield.sqlite";
};

TEST_F(YieldStore, EachTestKnowsItsAttempt) {
  auto store = db::Store::Open(db_, db::Store::Role::kReadOnly);
  const std::vector<db::TestRecord> u2 = store->TestsOfSerial("U2");
  ASSERT_EQ(u2.size(), 2u);
  EXPECT_EQ(u2[0].attempt, 2);  // newest first
  EXPECT_EQ(u2[1].attempt, 1);
  EXPECT_EQ(u2[0].max_tests, 3);
  const nlohmann::json summary = station::RecordSummary(u2[0]);
  EXPECT_EQ(summary.at("attempt"), 2);
  EXPECT_EQ(summary.at("max_tests"), 3);
  EXPECT_EQ(store->TestsOfSerial("U0").front().attempt, 2);  // its first was on the 19th
  // BeginTest tells the new test its attempt before it runs.
  auto writer = db::Store::Open(db_);
  db::TestRecord third = Record({"U2", "2026-11-22T07:00", Outcome::kPass, {}});
  writer->BeginTest(third);
  EXPECT_EQ(third.attempt, 3);
  // A record's stored "attempt" never overrides the columns' count.
  third.attempt = 42;
  third.finished_at = third.started_at;
  writer->FinishTest(third);
  EXPECT_EQ(writer->Test(third.id, false)->attempt, 3);
}

testing::CliRun Eol(const std::vector<std::string>& args) {
  return testing::RunEol(args, /*merge_stderr=*/true, 60s);
}

TEST_F(YieldStore, StatsYieldCommand) {
  const std::vector<std::string> base = {
      "stats", "--db", db_, "--yield", "--from", "2026-11-20", "--utc-offset-min", "0"};
  auto args = base;
  args.insert(args.end(), {"--by", "shift", "--json"});
  const testing::CliRun json = Eol(args);
  ASSERT_EQ(json.code, 0) << json.out;
  const nlohmann::json report = nlohmann::json::parse(json.out);
  ExpectTotal(report.at("total"));
  ExpectShifts(report);
  EXPECT_EQ(report.at("window").at("time_zone"), "UTC+00:00");
  EXPECT_EQ(report.at("window").at("shifts"), "A=06:00,B=14:00,C=22:00");

  args = base;
  const std::string svg = dir_ / "pareto.svg";
  args.insert(args.end(), {"--by", "day", "--plot", svg});
  const testing::CliRun text = Eol(args);
  ASSERT_EQ(text.code, 0) << text.out;
  for (const std::string line :
       {"yield by day (UTC+00:00", "2026-11-21", "limit 3 tests of 2 units (37.5 %, cum. 37.5 %)",
        "1 tests of serials first tested before the window", "Pareto chart written to"})
    EXPECT_NE(text.out.find(line), std::string::npos) << line << "\n" << text.out;
  // The total row: 8 units, 25 % first pass, 60 % first verdict, 50 % final, 1 FAIL, 3 open.
  EXPECT_NE(text.out.find("25.0 %    60.0 %    50.0 %     1     3"), std::string::npos) << text.out;
  std::stringstream drawn;
  drawn << std::ifstream(svg).rdbuf();
  EXPECT_NE(drawn.str().find("1 limit: 3 tests, 2 units"), std::string::npos);

  // Without --from, U0's first test is in the window: 9 units, nothing carried over.
  const testing::CliRun all = Eol({"stats", "--db", db_, "--yield", "--json"});
  ASSERT_EQ(all.code, 0) << all.out;
  EXPECT_EQ(nlohmann::json::parse(all.out)["total"]["units"], 9);
  EXPECT_EQ(nlohmann::json::parse(all.out)["total"]["carried_over_tests"], 0);

  for (const auto& [bad, message] : std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{"--yield", "--by", "week"}, "--by must be all, shift, day or recipe (have 'week')"},
           {{"--yield", "--shifts", "A=6"}, "--shifts: 'A=6' must be NAME=HH:MM"},
           {{"--yield", "--gauge", "U1"}, "--gauge is a capability option and does not apply"},
           {{"--by", "day"}, "--by needs --yield"},
           {{"--yield", "--utc-offset-min", "9999"}, "--utc-offset-min"}}) {
    std::vector<std::string> a = {"stats", "--db", db_};
    a.insert(a.end(), bad.begin(), bad.end());
    const testing::CliRun r = Eol(a);
    EXPECT_EQ(r.code, 2) << bad[0] << " " << bad.back() << ": " << r.out;
    EXPECT_NE(r.out.find(message), std::string::npos) << message << "\n" << r.out;
  }
}

// `eol query` marks each test with its attempt of the recipe's allowed tests.
TEST_F(YieldStore, QueryShowsTheAttempt) {
  const testing::CliRun q = Eol({"query", "--db", db_, "--serial", "U2"});
  ASSERT_EQ(q.code, 0) << q.out;
  EXPECT_NE(q.out.find("test 2 of 3 retest of #"), std::string::npos) << q.out;
  EXPECT_NE(q.out.find("test 1 of 3\n"), std::string::npos) << q.out;
  const testing::CliRun json = Eol({"query", "--db", db_, "--serial", "U2", "--json"});
  ASSERT_EQ(json.code, 0) << json.out;
  EXPECT_EQ(nlohmann::json::parse(json.out)["latest"]["attempt"], 2);
}

TEST_F(YieldStore, YieldApiAndParetoChart) {
  station::StatusBoard board("api");
  station::HttpOptions o;
  o.port = 0;
  o.db_path = db_;
  station::HttpApi api(board, o, {});
  api.Start();
  httplib::Client http("127.0.0.1", api.port());
  auto res = http.Get("/api/yield?by=shift&from=2026-11-20&utc_offset_min=0");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200) << res->body;
  const nlohmann::json report = nlohmann::json::parse(res->body);
  ExpectTotal(report.at("total"));
  ExpectShifts(report);
  EXPECT_EQ(report.at("window").at("by"), "shift");

  res = http.Get("/api/yield?by=recipe&recipe_hash=" + kHashB);
  ASSERT_TRUE(res);
  const nlohmann::json b = nlohmann::json::parse(res->body);
  ASSERT_EQ(b.at("groups").size(), 1u) << res->body;
  EXPECT_EQ(b.at("total").at("units"), 2);

  res = http.Get("/api/yield/pareto.svg?from=2026-11-20");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200) << res->body;
  EXPECT_EQ(res->get_header_value("Content-Type"), "image/svg+xml");
  EXPECT_NE(res->body.find("1 limit: 3 tests, 2 units"), std::string::npos);
  res = http.Get("/api/yield/pareto.svg?by=shift&utc_offset_min=0&group=2026-11-21%20A");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200) << res->body;
  EXPECT_NE(res->body.find("1 none: 1 tests, 1 units"), std::string::npos);

  for (const auto& [query, status, message] :
       std::vector<std::tuple<std::string, int, std::string>>{
           {"/api/yield?by=week", 400, "by must be all, shift, day or recipe"},
           {"/api/yield?shifts=A", 400, "shifts: 'A' must be NAME=HH:MM"},
           {"/api/yield?utc_offset_min=900", 400, "utc_offset_min"},
           {"/api/yield?from=2026-12-01&to=2026-11-01", 400, "from must be before to"},
           {"/api/yield?grup=day", 400, "unknown parameter 'grup'"},
           {"/api/yield?group=all", 400, "unknown parameter 'group'"},
           {"/api/yield/pareto.svg?by=day&group=1999-01-01", 404, "no group '1999-01-01' by day"},
           {"/api/yield/pareto.svg?recipe_hash=" + std::string(64, 'f'), 404,
            "no non-PASS test in all"}}) {
    res = http.Get(query);
    ASSERT_TRUE(res) << query;
    EXPECT_EQ(res->status, status) << query << ": " << res->body;
    EXPECT_NE(nlohmann::json::parse(res->body)["error"]["message"].get<std::string>().find(message),
              std::string::npos)
        << query << ": " << res->body;
  }
  api.Stop();
}

}  // namespace
}  // namespace eol
