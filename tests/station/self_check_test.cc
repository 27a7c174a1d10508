// Self-checks with master parts and the lockout (station/daemon/self_check.h), on the whole station
// (config, sim bench with its masters, real SQLite file, real HTTP on 127.0.0.1): production
// is refused with ERROR and the reason until both masters check out; a limit master that
// PASSes locks the station; the lockout survives a restart; a passing check unlocks.
#include "station/daemon/self_check.h"

#include <gtest/gtest.h>

#include <chrono>
#include <memory>

#include "../support/child_process.h"
#include "../support/manual_station_clock.h"
#include "station/daemon/station.h"
#include "station/reports/stats_report.h"

// After Eigen: <resolv.h> (through httplib) defines _res, a parameter name in Eigen.
#include <httplib.h>

namespace eol::station {
namespace {

using analysis::Outcome;

class SelfCheckTest : public ::testing::Test {
 protected:
  // limit_soft = false makes the sim's limit master a good rotor: a check that must fail.
  StationConfig Config(bool limit_soft, int every_n_tests = 50, double every_hours = 8) {
    const nlohmann::json j = {
        {"station_id", "sc"},
        {"recipe", std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json"},
        {"db", dir_ / "s.sqlite"},
        {"http", {{"listen", "127.0.0.1"}, {"port", 0}}},
        {"fixture", {{"driver", "sim"}}},
        {"daq", {{"driver", "sim"}}},
        {"sim",
         {{"clamp_close_s", 0.02},
          {"clamp_open_s", 0.02},
          {"population", {{"defect_share", 0.0}}},
          {"masters",
           {{{"serial", "MASTER-G"}}, {{"serial", "MASTER-L"}, {"defective", limit_soft}}}}}},
        {"self_check",
         {{"good_master", "MASTER-G"},
          {"limit_master", "MASTER-L"},
          {"every_n_tests", every_n_tests},
          {"every_hours", every_hours}}}};
    return ParseStationConfig(j, "test", "");
  }

  static std::string Reasons(const db::TestRecord& r) {
    std::string all;
    for (const auto& s : r.reasons) all += s.text + " | ";
    return all;
  }

  static nlohmann::json Lockout(Station& s) { return s.board().Snapshot()["lockout"]; }

  eol::testing::TempDir dir_;
};

TEST_F(SelfCheckTest, LockoutLifecycleSurvivesRestartAndUnlocksOnAPassingCheck) {
  {
    // The bench made here, so the test can see the clamp command never went out.
    StationConfig config = Config(true);
    auto bench = std::make_shared<drivers::SimBench>(
        drivers::ParseSimBenchSettings(io::JsonObject(config.drivers["sim"], "/sim")));
    drivers::DriverSet drivers = drivers::MakeDrivers(config.drivers, bench);
    Station s(std::move(config), std::move(drivers));
    ASSERT_TRUE(Lockout(s).at("locked").get<bool>());
    EXPECT_NE(
        Lockout(s)["reason"].get<std::string>().find("no self-check of the good master MASTER-G"),
        std::string::npos);
    // Never checked: production refused before anything moves, and nothing stored.
    const db::TestRecord refused = s.RunTest("U-1");
    EXPECT_EQ(refused.outcome, Outcome::kError);
    ASSERT_FALSE(refused.reasons.empty());
    EXPECT_EQ(refused.reasons.front().text.rfind("station locked out: no self-check", 0), 0u)
        << Reasons(refused);
    EXPECT_TRUE(s.store().TestsOfSerial("U-1").empty());
    EXPECT_FALSE(bench->output(drivers::FixtureOutput::kClampCmd));

    const db::TestRecord good = s.RunTest("MASTER-G");
    EXPECT_EQ(good.outcome, Outcome::kPass) << Reasons(good);
    EXPECT_EQ(good.kind, db::RecordKind::kSelfCheck);
    EXPECT_TRUE(good.self_check.at("passed").get<bool>()) << Reasons(good);
    EXPECT_TRUE(Lockout(s).at("locked").get<bool>());  // the limit master is still due
    const db::TestRecord limit = s.RunTest("MASTER-L");
    EXPECT_EQ(limit.outcome, Outcome::kFail) << Reasons(limit);
    EXPECT_TRUE(limit.self_check.at("passed").get<bool>()) << Reasons(limit);
    EXPECT_NE(
        Reasons(limit).find("self-check passed: limit master MASTER-L rejected on the resonance"),
        std::string::npos)
        << Reasons(limit);
    EXPECT_FALSE(Lockout(s).at("locked").get<bool>()) << Lockout(s).dump();

    const db::TestRecord unit = s.RunTest("U-1");
    EXPECT_EQ(unit.outcome, Outcome::kPass) << Reasons(unit);
    EXPECT_EQ(s.store().Test(unit.id)->kind, db::RecordKind::kProduction);
  }
  std::string failed_at;
  {
    // The limit master lost its soft bond (worn, swapped): it PASSes, so the check fails.
    Station s(Config(false));
    EXPECT_FALSE(Lockout(s).at("locked").get<bool>());
    const db::TestRecord limit = s.RunTest("MASTER-L");
    EXPECT_EQ(limit.outcome, Outcome::kPass) << Reasons(limit);
    EXPECT_FALSE(limit.self_check.at("passed").get<bool>());
    EXPECT_NE(Reasons(limit).find("self-check failed: limit master MASTER-L PASSed: the station "
                                  "would pass a soft-bonded rotor"),
              std::string::npos)
        << Reasons(limit);
    ASSERT_TRUE(Lockout(s).at("locked").get<bool>());
    failed_at = s.store().LatestSelfCheck("limit")->at;
    const db::TestRecord refused = s.RunTest("U-2");
    EXPECT_EQ(refused.outcome, Outcome::kError);
    ASSERT_FALSE(refused.reasons.empty());
    EXPECT_EQ(refused.reasons.front().text.rfind("station locked out: self-check failed at " +
                                                     failed_at + ": limit master MASTER-L PASSed",
                                                 0),
              0u)
        << Reasons(refused);
    EXPECT_TRUE(s.store().TestsOfSerial("U-2").empty());
  }
  {
    // Restart with the real soft master back: still locked, and shown on GET /api/status.
    Station s(Config(true));
    s.StartHttp();
    httplib::Client http("127.0.0.1", s.http_port());
    auto status = http.Get("/api/status");
    ASSERT_TRUE(status);
    const nlohmann::json lockout = nlohmann::json::parse(status->body).at("lockout");
    EXPECT_TRUE(lockout.at("locked").get<bool>()) << lockout.dump();
    EXPECT_NE(lockout.at("reason").get<std::string>().find("self-check failed at " + failed_at),
              std::string::npos);
    EXPECT_EQ(s.RunTest("U-2").outcome, Outcome::kError);

    const db::TestRecord limit = s.RunTest("MASTER-L");
    EXPECT_EQ(limit.outcome, Outcome::kFail) << Reasons(limit);
    status = http.Get("/api/status");
    ASSERT_TRUE(status);
    EXPECT_FALSE(nlohmann::json::parse(status->body)["lockout"]["locked"].get<bool>());
    EXPECT_EQ(s.RunTest("U-2").outcome, Outcome::kPass);

    // Masters' tests are stored, flagged, and kept out of production statistics.
    EXPECT_EQ(s.store().SelfChecks().size(), 4u);
    auto stats = http.Get("/api/stats");
    ASSERT_TRUE(stats);
    ASSERT_EQ(stats->status, 200) << stats->body;
    const nlohmann::json report = nlohmann::json::parse(stats->body);
    ASSERT_EQ(report["recipes"].size(), 1u) << report.dump();
    EXPECT_EQ(report["recipes"][0]["tests"], 2);  // U-1 and U-2, no master
  }
}

TEST_F(SelfCheckTest, ACheckIsDueAfterEveryNTestsAndAfterEveryHours) {
  {
    Station s(Config(true, 2));
    EXPECT_EQ(s.RunTest("MASTER-G").outcome, Outcome::kPass);
    EXPECT_EQ(s.RunTest("MASTER-L").outcome, Outcome::kFail);
    EXPECT_EQ(s.RunTest("U-1").outcome, Outcome::kPass);
    EXPECT_EQ(s.RunTest("U-2").outcome, Outcome::kPass);
    const db::TestRecord due = s.RunTest("U-3");
    EXPECT_EQ(due.outcome, Outcome::kError);
    ASSERT_FALSE(due.reasons.empty());
    EXPECT_NE(
        due.reasons.front().text.find("station locked out: self-check due: 2 production tests "
                                      "since the last check"),
        std::string::npos)
        << Reasons(due);
    // Both masters again: the older check sets the window, so one master is not enough.
    EXPECT_EQ(s.RunTest("MASTER-G").outcome, Outcome::kPass);
    EXPECT_EQ(s.RunTest("U-3").outcome, Outcome::kError);
    EXPECT_EQ(s.RunTest("MASTER-L").outcome, Outcome::kFail);
    EXPECT_EQ(s.RunTest("U-3").outcome, Outcome::kPass);
  }
  {
    // A check valid for 8 h, on a calendar the test moves (the station's wall clock): valid
    // just before the 8 h are over, production refused once they are.
    auto calendar = std::make_shared<drivers::ManualClock>();
    Station s(Config(true, 0, 8), {}, eol::testing::ManualWallClock(calendar));
    EXPECT_EQ(s.RunTest("MASTER-G").outcome, Outcome::kPass);
    EXPECT_EQ(s.RunTest("MASTER-L").outcome, Outcome::kFail);
    calendar->Advance(std::chrono::hours(8) - std::chrono::minutes(1));
    const db::TestRecord valid = s.RunTest("U-4");
    EXPECT_EQ(valid.outcome, Outcome::kPass) << Reasons(valid);
    calendar->Advance(std::chrono::minutes(2));
    const db::TestRecord due = s.RunTest("U-5");
    EXPECT_EQ(due.outcome, Outcome::kError);
    ASSERT_FALSE(due.reasons.empty());
    EXPECT_NE(due.reasons.front().text.find("self-check due: the last check"), std::string::npos)
        << Reasons(due);
    EXPECT_NE(due.reasons.front().text.find("is older than 8 h"), std::string::npos)
        << Reasons(due);
  }
}

TEST(SelfCheckConfig, InvalidSectionsNameThePath) {
  auto message = [](const nlohmann::json& self_check) {
    const nlohmann::json j = {{"recipe", "r.json"},
                              {"db", "d.sqlite"},
                              {"fixture", {{"driver", "sim"}}},
                              {"daq", {{"driver", "sim"}}},
                              {"self_check", self_check}};
    try {
      ParseStationConfig(j, "c.json", "");
    } catch (const io::ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("(accepted)");
  };
  EXPECT_NE(message({{"good_master", "G"}}).find("/self_check/limit_master"), std::string::npos);
  EXPECT_NE(message({{"good_master", "G"}, {"limit_master", "G"}})
                .find("/self_check/limit_master: must differ from good_master"),
            std::string::npos);
  EXPECT_NE(message({{"good_master", "G"}, {"limit_master", "L"}, {"every_n_tests", -1}})
                .find("/self_check/every_n_tests: must be in [0, 100000]"),
            std::string::npos);
  EXPECT_NE(
      message({{"good_master", "G"}, {"limit_master", "L"}, {"every_day", 1}}).find("every_day"),
      std::string::npos);
  EXPECT_EQ(message({{"good_master", "G"}, {"limit_master", "L"}}), "(accepted)");
}

}  // namespace
}  // namespace eol::station
