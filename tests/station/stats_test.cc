// Statistics (station/reports/stats_report.h) end to end: known answers through `eol stats` and
// GET /api/stats on a real store, and the drift alarm on the simulated station with and
// without fixture wear (fixed seeds).
#include <gtest/gtest.h>

#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "../support/child_process.h"
#include "db/store.h"
#include "station/daemon/http_api.h"
#include "station/daemon/station.h"
#include "station/reports/stats_report.h"
#include "tests/support/eol_cli.h"

// After Eigen: <resolv.h> (through httplib) defines _res, a parameter name in Eigen.
#include <httplib.h>

namespace eol {
namespace {

using namespace std::chrono_literals;
using analysis::Outcome;
using eol::testing::ChildProcess;

const std::string kHashA(64, 'a');  // the known-answer recipe
const std::string kHashD(64, 'd');  // a drifting one

db::TestRecord Record(const std::string& serial, int minute, Outcome o, double f0,
                      const std::string& hash = kHashA,
                      db::RecordKind kind = db::RecordKind::kProduction) {
  char t[32];
  std::snprintf(t, sizeof t, "2026-11-20T%02d:%02d:00.000Z", 8 + minute / 60, minute % 60);
  db::TestRecord r;
  r.serial = serial;
  r.station_id = "s1";
  r.recipe_id = hash == kHashA ? "pmsm-10pole" : "drifting";
  r.recipe_version = 1;
  r.recipe_hash = hash;
  r.software_version = "test";
  r.started_at = t;
  r.finished_at = t;
  r.outcome = o;
  r.kind = kind;
  if (kind == db::RecordKind::kSelfCheck)
    r.self_check = {{"master", "good"}, {"passed", true}, {"detail", ""}};
  analysis::Measurement m;
  m.name = "resonance_f_hz";
  m.unit = "Hz";
  m.value = f0;
  m.limit.lo = 370;
  m.limit.hi = 420;
  m.outcome = analysis::MeasurementOutcome::kPass;
  r.measurements.push_back(m);
  return r;
}

using eol::testing::CliRun;

CliRun Eol(const std::vector<std::string>& args, bool merge_stderr = false) {
  return testing::RunEol(args, merge_stderr, 60s);
}

const nlohmann::json& Measurement(const nlohmann::json& recipe, const std::string& name) {
  for (const auto& m : recipe.at("measurements"))
    if (m.at("name") == name) return m;
  throw std::runtime_error("no measurement " + name + " in " + recipe.dump());
}

class StatsKnownAnswer : public ::testing::Test {
 protected:
  void SetUp() override {
    auto store = db::Store::Open(db_);
    // Production under recipe A: 388..392, mean 390, s = sqrt(10 / 4) = 1.58113883;
    // Pp = 50 / (6 s) = 5.27046277, Ppk = min(420 - 390, 390 - 370) / (3 s) = 4.21637021.
    // Moving ranges all 1: sigma within = 1 / 1.128; Cp = 50 * 1.128 / 6 = 9.4,
    // Cpk = 20 * 1.128 / 3 = 7.52.
    int minute = 0;
    for (double f : {388.0, 389.0, 390.0, 391.0, 392.0}) {
      auto r = Record("P-" + std::to_string(minute), minute, Outcome::kPass, f);
      store->Insert(r);
      ++minute;
    }
    // An ERROR test (its value says nothing about a motor) and a master: neither counts.
    auto e = Record("P-ERR", minute++, Outcome::kError, 0.0);
    store->Insert(e);
    // Gauge part: ten repeats 389..391 (six at +-1, four at 0): s = sqrt(6 / 9) = 0.81649658;
    // Cg = 0.2 * 50 / (6 s) = 2.04124145; reference 389.5, bias 0.5:
    // Cgk = (5 - 0.5) / (3 s) = 1.83711731.
    for (double f : {389.0, 390.0, 391.0, 390.0, 389.0, 391.0, 390.0, 390.0, 389.0, 391.0}) {
      auto r = Record("MASTER-G", minute++, Outcome::kPass, f, kHashA, db::RecordKind::kSelfCheck);
      store->Insert(r);
    }
    // Recipe D drifts: 380 + i + 0.5 (-1)^i over 20 passing tests (+19 Hz, 38 % of 50 Hz).
    for (int i = 0; i < 20; ++i) {
      auto r = Record("D-" + std::to_string(i), minute++, Outcome::kPass,
                      380.0 + i + 0.5 * (i % 2 == 0 ? 1 : -1), kHashD);
      store->Insert(r);
    }
  }

  static void ExpectKnownAnswers(const nlohmann::json& report) {
    const nlohmann::json* a = nullptr;
    for (const auto& g : report.at("recipes"))
      if (g.at("recipe_hash") == kHashA) a = &g;
    ASSERT_NE(a, nullptr) << report.dump();
    EXPECT_EQ(a->at("tests"), 6);  // five measured units and the ERROR test
    EXPECT_EQ(a->at("outcomes").at("ERROR"), 1);
    const nlohmann::json& f0 = Measurement(*a, "resonance_f_hz");
    EXPECT_EQ(f0.at("n"), 5);
    EXPECT_NEAR(f0.at("mean").get<double>(), 390.0, 1e-9);
    EXPECT_NEAR(f0.at("sd").get<double>(), 1.58113883, 1e-8);
    EXPECT_NEAR(f0.at("pp").get<double>(), 5.27046277, 1e-7);
    EXPECT_NEAR(f0.at("ppk").get<double>(), 4.21637021, 1e-7);
    EXPECT_NEAR(f0.at("cp").get<double>(), 9.4, 1e-9);
    EXPECT_NEAR(f0.at("cpk").get<double>(), 7.52, 1e-9);
    EXPECT_EQ(f0.at("population"), "PASS and FAIL units");  // every measured unit by default
    // 5 units: the index comes with its caveat and the interval of Cpk (1.96 sqrt(1/45 +
    // 7.52^2/8) = 5.219 either side).
    EXPECT_EQ(f0.at("caveat"),
              "only 5 units (30 or more for a capability index): Cpk 7.52 lies in about [2.301, "
              "12.74] (95 %)");
    EXPECT_EQ(f0.at("sigma_within_method"), "MRbar/d2 (d2 = 1.128)");
    EXPECT_FALSE(f0.at("drift").at("usable").get<bool>());  // 5 < 10 tests
  }

  static void ExpectGauge(const nlohmann::json& gauge) {
    EXPECT_EQ(gauge.at("serial"), "MASTER-G");
    EXPECT_EQ(gauge.at("tests"), 10);
    const nlohmann::json& g = gauge.at("measurements").at(0);
    EXPECT_EQ(g.at("name"), "resonance_f_hz");
    EXPECT_NEAR(g.at("sd").get<double>(), 0.81649658, 1e-8);
    EXPECT_NEAR(g.at("cg").get<double>(), 2.04124145, 1e-7);
    EXPECT_NEAR(g.at("cgk").get<double>(), 1.83711731, 1e-7);
    EXPECT_EQ(g.at("capable"), true);
  }

  eol::testing::TempDir dir_;
  std::string db_ = dir_ / "stats.sqlite";
};

TEST_F(StatsKnownAnswer, CliCapabilityGaugeAndDriftExitCode) {
  const CliRun a = Eol({"stats", "--db", db_, "--recipe-hash", kHashA, "--gauge", "MASTER-G",
                        "--reference", "resonance_f_hz=389.5", "--json"});
  ASSERT_EQ(a.code, 0) << a.out;
  const nlohmann::json report = nlohmann::json::parse(a.out);
  ASSERT_EQ(report.at("recipes").size(), 1u);
  ExpectKnownAnswers(report);
  ExpectGauge(report.at("gauge"));
  EXPECT_TRUE(report.at("alarms").empty());

  // Every recipe: the drifting one raises the alarm and the exit code says so.
  const CliRun all = Eol({"stats", "--db", db_, "--json"});
  EXPECT_EQ(all.code, 1) << all.out;
  const nlohmann::json both = nlohmann::json::parse(all.out);
  ExpectKnownAnswers(both);
  ASSERT_EQ(both.at("alarms").size(), 1u);
  EXPECT_NE(
      both["alarms"][0].get<std::string>().find("drifting v1: drift alarm: resonance_f_hz rises"),
      std::string::npos)
      << both["alarms"][0];

  const CliRun text = Eol({"stats", "--db", db_, "--gauge", "MASTER-G"});
  EXPECT_EQ(text.code, 1);
  EXPECT_NE(text.out.find("recipe pmsm-10pole v1 (aaaaaaaaaaaa): 6 production tests"),
            std::string::npos)
      << text.out;
  EXPECT_NE(text.out.find("ALARM drifting v1: drift alarm"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find(
                "type-1 gauge study of MASTER-G: 10 tests (K = 20 % of the tolerance, 6 sigma)"),
            std::string::npos)
      << text.out;
  EXPECT_NE(text.out.find("no reference value"), std::string::npos) << text.out;

  const CliRun bad = Eol({"stats", "--db", db_, "--reference", "resonance_f_hz"}, true);
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.out.find("--reference: reference 'resonance_f_hz' must be NAME=VALUE"),
            std::string::npos)
      << bad.out;
  const CliRun span = Eol({"stats", "--db", db_, "--gauge-sigma-span", "5"}, true);
  EXPECT_EQ(span.code, 2);
  EXPECT_NE(span.out.find("gauge: sigma_span must be 4 or 6"), std::string::npos) << span.out;
}

TEST_F(StatsKnownAnswer, ApiServesTheSameReport) {
  station::StatusBoard board("api");
  station::HttpOptions o;
  o.port = 0;
  o.db_path = db_;
  station::HttpApi api(board, o, {});
  api.Start();
  httplib::Client http("127.0.0.1", api.port());
  auto res = http.Get("/api/stats?recipe_hash=" + kHashA +
                      "&gauge=MASTER-G&reference=resonance_f_hz:389.5");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200) << res->body;
  const nlohmann::json report = nlohmann::json::parse(res->body);
  ExpectKnownAnswers(report);
  ExpectGauge(report.at("gauge"));

  // A window that holds only the first three tests: 388, 389, 390.
  res = http.Get("/api/stats?from=2026-11-20T08:00:00.000Z&to=2026-11-20T08:03:00.000Z");
  ASSERT_TRUE(res);
  const nlohmann::json window = nlohmann::json::parse(res->body);
  ASSERT_EQ(window.at("recipes").size(), 1u) << res->body;
  EXPECT_EQ(Measurement(window["recipes"][0], "resonance_f_hz").at("n"), 3);
  EXPECT_NEAR(Measurement(window["recipes"][0], "resonance_f_hz").at("mean").get<double>(), 389.0,
              1e-9);

  for (const auto& [query, message] : std::vector<std::pair<std::string, std::string>>{
           {"/api/stats?sigma_span=5", "sigma_span must be 4 or 6"},
           {"/api/stats?from=2026-12-01&to=2026-11-01", "from must be before to"},
           {"/api/stats?reference=f0", "must be NAME=VALUE"},
           {"/api/stats?gauge=", "gauge: "}}) {
    res = http.Get(query);
    ASSERT_TRUE(res) << query;
    EXPECT_EQ(res->status, 400) << query;
    EXPECT_NE(nlohmann::json::parse(res->body)["error"]["message"].get<std::string>().find(message),
              std::string::npos)
        << query << ": " << res->body;
  }
  api.Stop();
}

// The whole station on the simulated bench, 40 units: fixture wear of 0.3 % of the fixture
// stiffness per part lowers f0 by about 16 Hz over the run (the fixture spring carries ~35 %
// of d ln f0); with no wear the same units show no alarm.
nlohmann::json DriftRun(const eol::testing::TempDir& dir, const std::string& name, double wear) {
  const nlohmann::json j = {
      {"station_id", name},
      {"recipe", std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json"},
      {"db", dir / (name + ".sqlite")},
      {"fixture", {{"driver", "sim"}}},
      {"daq", {{"driver", "sim"}}},
      {"sim", {{"clamp_close_s", 0.02}, {"clamp_open_s", 0.02}, {"fixture_wear_per_test", wear}}}};
  station::Station s(station::ParseStationConfig(j, "test", ""));
  for (int i = 0; i < 40; ++i) {
    char serial[16];
    std::snprintf(serial, sizeof serial, "W-%03d", i);
    const db::TestRecord r = s.RunTest(serial);
    EXPECT_NE(r.outcome, Outcome::kError)
        << serial << ": " << (r.reasons.empty() ? "" : r.reasons[0].text);
  }
  return station::StatsReport(s.store(), {});
}

TEST(StatsDrift, FixtureWearRaisesTheAlarmAndNoWearDoesNot) {
  eol::testing::TempDir dir;
  const nlohmann::json worn = DriftRun(dir, "worn", 0.003);
  const nlohmann::json& f0 = Measurement(worn.at("recipes").at(0), "resonance_f_hz");
  const nlohmann::json& drift = f0.at("drift");
  EXPECT_TRUE(drift.at("alarm").get<bool>()) << drift.dump();
  EXPECT_LT(drift.at("slope_per_test").get<double>(), 0.0);
  EXPECT_LT(drift.at("t").get<double>(), -4.0);
  ASSERT_FALSE(worn.at("alarms").empty());
  EXPECT_NE(worn["alarms"][0].get<std::string>().find("drift alarm: resonance_f_hz falls"),
            std::string::npos)
      << worn["alarms"][0];

  std::cout << "worn: " << worn["alarms"][0].get<std::string>() << "\n";
  const nlohmann::json fresh = DriftRun(dir, "fresh", 0.0);
  const nlohmann::json& f0_fresh = Measurement(fresh.at("recipes").at(0), "resonance_f_hz");
  EXPECT_FALSE(f0_fresh.at("drift").at("alarm").get<bool>()) << f0_fresh.dump();
  EXPECT_TRUE(f0_fresh.at("drift").at("usable").get<bool>());
  EXPECT_TRUE(fresh.at("alarms").empty()) << fresh.at("alarms").dump();
  std::cout << "fresh: " << f0_fresh["drift"]["message"].get<std::string>() << "\n";
  // Wear also shows in the capability: the worn run's f0 spreads more than the fresh one's.
  EXPECT_GT(f0.at("sd").get<double>(), f0_fresh.at("sd").get<double>());
}

}  // namespace
}  // namespace eol
