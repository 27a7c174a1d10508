// Issue 14, safe defaults: the packaged configuration cannot test in production until it is
// edited; a station on simulators says SIMULATION on its board and in every record; "ready"
// means the fixture and the DAQ answered. Real recipe file, real SQLite store, a real TCP
// port that refuses connections as the unreachable fixture controller.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "drivers/io/json_config.h"
#include "station/daemon/station.h"
#include "tests/support/child_process.h"

namespace eol::station {
namespace {

nlohmann::json ConfigWith(const eol::testing::TempDir& dir, nlohmann::json fixture,
                          nlohmann::json daq) {
  return {{"station_id", "defaults"},
          {"recipe", std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json"},
          {"db", dir / "s.sqlite"},
          {"fixture", std::move(fixture)},
          {"daq", std::move(daq)}};
}

TEST(StationDefaults, PackagedConfigNamesRealDriversNotSimulators) {
  const nlohmann::json packaged =
      io::ReadJsonFile(std::string(EOL_SOURCE_DIR) + "/deploy/debian/station.json");
  const StationConfig c = ParseStationConfig(packaged, "station.json", "/etc/eol");
  EXPECT_EQ(SimulationReason(c), "") << "the package would test on simulators";
  EXPECT_EQ(c.http_listen, "127.0.0.1");
  // The demo's config names its simulators, and the reason says which.
  const StationConfig demo =
      LoadStationConfig(std::string(EOL_SOURCE_DIR) + "/deploy/station.json");
  EXPECT_EQ(SimulationReason(demo), "fixture driver 'sim', daq driver 'sim'");
}

TEST(StationDefaults, SimulatorsAreMarkedOnTheBoardAndInEveryRecord) {
  eol::testing::TempDir dir;
  Station s(ParseStationConfig(ConfigWith(dir, {{"driver", "sim"}}, {{"driver", "sim"}}), "t", ""));
  EXPECT_TRUE(s.ready());
  EXPECT_EQ(s.board().Snapshot()["simulation"], "fixture driver 'sim', daq driver 'sim'");
  const db::TestRecord r = s.RunTest("SIM-1");
  ASSERT_TRUE(r.conditions.simulation.has_value()) << nlohmann::json(r.conditions).dump();
  const auto stored = s.store().Test(r.id);
  ASSERT_TRUE(stored.has_value());
  EXPECT_EQ(stored->conditions.simulation, "fixture driver 'sim', daq driver 'sim'");
}

TEST(StationDefaults, NotReadyUntilTheFixtureAnswers) {
  eol::testing::TempDir dir;
  // Port 1 on loopback: nothing listens, the connection is refused at once.
  Station s(ParseStationConfig(
      ConfigWith(dir, {{"driver", "modbus-tcp"}, {"host", "127.0.0.1"}, {"port", 1}},
                 {{"driver", "sim"}}),
      "t", ""));
  EXPECT_FALSE(s.ready());
  const nlohmann::json board = s.board().Snapshot();
  EXPECT_FALSE(board["ready"].get<bool>());
  EXPECT_NE(board["not_ready_reason"].get<std::string>().find("127.0.0.1:1"), std::string::npos)
      << board.dump();
  EXPECT_EQ(board["simulation"], "daq driver 'sim'");
  const db::TestRecord r = s.RunTest("NR-1");
  EXPECT_EQ(r.outcome, analysis::Outcome::kError);
  ASSERT_FALSE(r.reasons.empty());
  EXPECT_NE(r.reasons.front().text.find("fixture unavailable"), std::string::npos)
      << r.reasons.front().text;
  EXPECT_FALSE(s.ready());
}

// Issue 14: a recipe file that does not load at start (edited by hand) neither stops the
// daemon for good nor tests with it: the newest kept version is shown, tests are refused
// with the cause, and a valid recipe installed over the API lifts the refusal.
TEST(StationDefaults, ARecipeThatDoesNotLoadRefusesTestsButKeepsTheStationUp) {
  eol::testing::TempDir dir;
  const std::string path = dir / "pmsm-10pole.json";
  nlohmann::json good = io::ReadJsonFile(std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json");
  {
    std::ofstream kept(dir / "pmsm-10pole.v1.json");
    kept << good.dump(2);
    nlohmann::json bad = good;
    bad["version"] = 2;
    bad["excitation"]["sample_rate_hz"] = 1e10;
    std::ofstream broken(path);
    broken << bad.dump(2);
  }
  nlohmann::json config = ConfigWith(dir, {{"driver", "sim"}}, {{"driver", "sim"}});
  config["recipe"] = path;
  Station s(ParseStationConfig(config, "t", ""));
  EXPECT_EQ(s.recipe()->version, 1);
  EXPECT_FALSE(s.ready());
  std::string why;
  EXPECT_FALSE(s.Enqueue("R-1", &why));
  EXPECT_NE(why.find("/excitation/sample_rate_hz"), std::string::npos) << why;
  EXPECT_NE(why.find("tests are refused"), std::string::npos) << why;
  EXPECT_NE(s.board().Snapshot()["message"].get<std::string>().find("sample_rate_hz"),
            std::string::npos);

  good["version"] = 3;
  const ApiToken anna{"qe-anna", Role::kEngineer, "engineer-token-0123456789"};
  const RecipeChange change = s.ChangeRecipe(good, anna);
  ASSERT_EQ(change.kind, RecipeChange::Kind::kChanged) << change.message;
  EXPECT_TRUE(s.Enqueue("R-2", &why)) << why;
  EXPECT_TRUE(s.ready());
}

// Fixing the recipe lifts only the recipe's refusal: a fixture that never answered keeps the
// station "not ready" with its own cause.
TEST(StationDefaults, FixingTheRecipeDoesNotHideAnUnreachableFixture) {
  eol::testing::TempDir dir;
  const std::string path = dir / "pmsm-10pole.json";
  nlohmann::json good = io::ReadJsonFile(std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json");
  {
    std::ofstream kept(dir / "pmsm-10pole.v1.json");
    kept << good.dump(2);
    std::ofstream broken(path);
    broken << "{\"id\": \"pmsm-10pole\"";
  }
  nlohmann::json config = ConfigWith(
      dir, {{"driver", "modbus-tcp"}, {"host", "127.0.0.1"}, {"port", 1}}, {{"driver", "sim"}});
  config["recipe"] = path;
  Station s(ParseStationConfig(config, "t", ""));
  EXPECT_FALSE(s.ready());
  good["version"] = 2;
  const ApiToken anna{"qe-anna", Role::kEngineer, "engineer-token-0123456789"};
  ASSERT_EQ(s.ChangeRecipe(good, anna).kind, RecipeChange::Kind::kChanged);
  EXPECT_FALSE(s.ready());
  EXPECT_NE(s.board().Snapshot()["not_ready_reason"].get<std::string>().find("fixture"),
            std::string::npos)
      << s.board().Snapshot().dump();
}

TEST(StationDefaults, ARecipeThatDoesNotLoadWithNoKeptVersionIsAConfigError) {
  eol::testing::TempDir dir;
  const std::string path = dir / "r.json";
  {
    std::ofstream broken(path);
    broken << "{\"id\": \"r\"";
  }
  nlohmann::json config = ConfigWith(dir, {{"driver", "sim"}}, {{"driver", "sim"}});
  config["recipe"] = path;
  EXPECT_THROW(Station(ParseStationConfig(config, "t", "")), io::ConfigError);
}

}  // namespace
}  // namespace eol::station
