// Issue 16/17: where a test's time goes (station/daemon/cycle_time.h), stored in every record, and
// the station's Prometheus metrics over its real HTTP server (station/daemon/station_metrics.h):
// a real SQLite file, the simulated bench, and an unreachable Modbus fixture for the errors.
#include <gtest/gtest.h>

#include <map>
#include <regex>
#include <string>

#include "station/daemon/cycle_time.h"
#include "station/daemon/station.h"
#include "tests/support/child_process.h"

// After Eigen: <resolv.h> (through httplib) defines _res, a parameter name in Eigen.
#include <httplib.h>

namespace eol::station {
namespace {

nlohmann::json ConfigWith(const eol::testing::TempDir& dir, nlohmann::json fixture) {
  return {{"station_id", "cycle-1"},
          {"recipe", std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json"},
          {"db", dir / "s.sqlite"},
          {"http", {{"listen", "127.0.0.1"}, {"port", 0}}},
          {"fixture", std::move(fixture)},
          {"daq", {{"driver", "sim"}}}};
}

// Every sample line "name{labels} value" of the exposition, keyed by "name{labels}".
std::map<std::string, double> Samples(const std::string& text) {
  std::map<std::string, double> out;
  const std::regex line(R"(^([a-z_]+(\{[^}]*\})?) ([-+0-9.eE]+|NaN|\+Inf)$)");
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t end = text.find('\n', start);
    const std::string l = text.substr(start, end - start);
    std::smatch m;
    if (std::regex_match(l, m, line)) out[m[1]] = std::stod(m[3]);
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return out;
}

std::string Metrics(const Station& s) {
  httplib::Client http("127.0.0.1", s.http_port());
  auto res = http.Get("/metrics");
  if (!res || res->status != 200) return "";
  return res->body;
}

TEST(CycleTime, StepsAreSummedFromTheTraceAndAddUpToTheTotal) {
  const std::vector<db::StateEntry> trace = {
      {"wait_serial", 0.0, ""},   {"check_interlocks", 2.0, ""}, {"clamp", 3.0, ""},
      {"confirm_clamp", 4.0, ""}, {"excite", 154.0, ""},         {"analyse", 654.0, ""},
      {"clamp", 670.0, ""},       {"excite", 671.0, ""},         {"analyse", 1171.0, ""},
      {"judge", 1190.0, ""},      {"unclamp", 1191.0, ""}};
  const auto c = CycleBreakdown(trace, 1300.0);
  EXPECT_DOUBLE_EQ(c.at("start"), 0.002);
  EXPECT_DOUBLE_EQ(c.at("clamp"), 0.151 + 0.001);
  EXPECT_DOUBLE_EQ(c.at("excitation"), 1.0);
  EXPECT_DOUBLE_EQ(c.at("analysis"), 0.016 + 0.019);
  EXPECT_DOUBLE_EQ(c.at("unclamp"), 0.109);
  EXPECT_DOUBLE_EQ(c.at("total"), 1.3);
  EXPECT_EQ(c.count("store"), 0u);
  double sum = 0;
  for (const auto& [step, s] : c)
    if (step != "total") sum += s;
  EXPECT_NEAR(sum, 1.3, 1e-12);
  EXPECT_NEAR(StationOverheadS(c), 1.3 - 0.152 - 1.0 - 0.109, 1e-12);
}

TEST(CycleTime, EveryRecordCarriesItsBreakdownAndMetricsCountIt) {
  eol::testing::TempDir dir;
  Station s(ParseStationConfig(ConfigWith(dir, {{"driver", "sim"}}), "t", ""));
  s.StartHttp("");
  int passed = 0;
  for (const char* serial : {"CYC-1", "CYC-2"}) {
    const db::TestRecord r = s.RunTest(serial);
    passed += r.outcome == analysis::Outcome::kPass;
    for (const char* step : {"start", "interlocks", "clamp", "excitation", "analysis", "judge",
                             "unclamp", "store", "publish", "total"})
      EXPECT_TRUE(r.cycle_s.count(step)) << step;
    double sum = 0;
    for (const auto& [step, t] : r.cycle_s)
      if (step != "total") sum += t;
    EXPECT_NEAR(sum, r.cycle_s.at("total"), 1e-9);
    // The stored record has every step up to its own store.
    const auto stored = s.store().Test(r.id);
    ASSERT_TRUE(stored.has_value());
    EXPECT_TRUE(stored->cycle_s.count("excitation"));
    EXPECT_EQ(stored->cycle_s.count("store"), 0u);
    EXPECT_LE(stored->cycle_s.at("total"), r.cycle_s.at("total"));
    EXPECT_DOUBLE_EQ(stored->cycle_s.at("excitation"), r.cycle_s.at("excitation"));
  }
  const auto m = Samples(Metrics(s));
  ASSERT_FALSE(m.empty());
  EXPECT_EQ(m.at(R"(eol_tests_total{outcome="pass",reason="none"})"), passed);
  EXPECT_EQ(m.at("eol_cycle_seconds_count"), 2);
  EXPECT_EQ(m.at(R"(eol_step_seconds_count{step="excitation"})"), 2);
  EXPECT_EQ(m.at(R"(eol_step_seconds_count{step="store"})"), 2);
  EXPECT_EQ(m.at("eol_station_overhead_seconds_count"), 2);
  EXPECT_EQ(m.at("eol_simulation"), 1);
  EXPECT_EQ(m.at("eol_ready"), 1);
  EXPECT_EQ(m.at("eol_testing"), 0);
  EXPECT_EQ(m.at("eol_fixture_errors_total"), 0);
  EXPECT_GT(m.at("eol_db_size_bytes"), 0);
  EXPECT_GT(m.at("eol_disk_free_bytes"), 0);
  EXPECT_TRUE(m.count("eol_last_resonance_hz"));
  bool info = false;
  for (const auto& [k, v] : m)
    info = info || (k.rfind("eol_info{", 0) == 0 && k.find(R"(station_id="cycle-1")") != k.npos);
  EXPECT_TRUE(info);
}

// Issue 16: the station config's publish_before_release stores and publishes while a slow
// clamp (0.4 s of travel, heartbeat every 20 ms) opens; the cycle ends with the verdict.
TEST(CycleTime, PublishBeforeReleaseTakesTheClampTravelOutOfTheCycle) {
  std::map<bool, double> unclamp_s;
  for (const bool early : {false, true}) {
    eol::testing::TempDir dir;
    nlohmann::json cfg = ConfigWith(dir, {{"driver", "sim"}});
    cfg["sim"] = {{"clamp_open_s", 0.4}, {"heartbeat_period_s", 0.02}};
    cfg["publish_before_release"] = early;
    Station s(ParseStationConfig(cfg, "t", ""));
    const db::TestRecord r = s.RunTest(early ? "EARLY-1" : "LATE-1");
    EXPECT_EQ(r.outcome, analysis::Outcome::kPass);
    unclamp_s[early] = r.cycle_s.at("unclamp");
    EXPECT_EQ(r.trace.back().state, "wait_serial");
    EXPECT_EQ(r.trace[r.trace.size() - 2].state, early ? "confirm_release" : "publish");
  }
  EXPECT_GE(unclamp_s[false], 0.39);
  EXPECT_LT(unclamp_s[true], 0.3);
}

TEST(CycleTime, FixtureErrorsAndReasonsAreCounted) {
  eol::testing::TempDir dir;
  // Port 1 on loopback: nothing listens, every connection is refused.
  Station s(ParseStationConfig(
      ConfigWith(dir, {{"driver", "modbus-tcp"}, {"host", "127.0.0.1"}, {"port", 1}}), "t", ""));
  s.StartHttp("");
  const db::TestRecord r = s.RunTest("CYC-E");
  ASSERT_EQ(r.outcome, analysis::Outcome::kError);
  const auto m = Samples(Metrics(s));
  EXPECT_EQ(m.at(R"(eol_tests_total{outcome="error",reason="fixture"})"), 1);
  EXPECT_GE(m.at("eol_fixture_errors_total"), 2);  // at start and at the test
  EXPECT_EQ(m.at("eol_ready"), 0);
  EXPECT_EQ(m.count(R"(eol_tests_total{outcome="pass",reason="none"})"), 0u);
}

}  // namespace
}  // namespace eol::station
