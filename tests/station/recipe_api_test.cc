// Recipe changes over the API: engineers only, validated, version must increase, the old
// file kept, the audit log written, and the next test judged with the new recipe.
#include <gtest/gtest.h>
#include <httplib.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>

#include "../support/child_process.h"
#include "../support/station_ready.h"
#include "../support/token_station.h"
#include "../support/wait_until.h"
#include "db/store.h"
#include "drivers/io/json_config.h"

namespace eol {
namespace {

using namespace std::chrono_literals;
using eol::testing::ChildProcess;

constexpr char kOperator[] = "operator-token-0123456789";
constexpr char kEngineer[] = "engineer-token-0123456789";

using eol::testing::PortFromReadyLine;

TEST(RecipeApi, EngineersChangeRecipesAuditedAndVersioned) {
  eol::testing::TempDir dir;
  const std::string recipe_path = dir / "pmsm-10pole.json";
  std::filesystem::copy_file(std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json",
                             recipe_path);
  std::ofstream(dir / "station.json")
      << testing::TokenStationConfig("recipe-api", "pmsm-10pole.json", kOperator, kEngineer).dump();
  ChildProcess station({EOL_BINARY, "station", "--config", dir / "station.json"});
  ASSERT_TRUE(station.WaitFor([](const std::string& o) { return PortFromReadyLine(o) > 0; }, 30s))
      << station.output();
  httplib::Client http("127.0.0.1", PortFromReadyLine(station.output()));
  auto with = [](const char* token) {
    return httplib::Headers{{"Authorization", std::string("Bearer ") + token}};
  };

  nlohmann::json recipe = io::ReadJsonFile(recipe_path);
  const std::string old_hash = nlohmann::json::parse(http.Get("/api/recipe")->body)["hash"];
  recipe["version"] = 2;
  recipe["limits"][0]["lo"] = 372;

  // Nobody without a token, operators not at all.
  auto res = http.Put("/api/recipe", recipe.dump(), "application/json");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 401);
  res = http.Put("/api/recipe", with(kOperator), recipe.dump(), "application/json");
  EXPECT_EQ(res->status, 403);
  // Starting a test needs a token too, and an operator's will do.
  res = http.Post("/api/tests", R"({"serial": "RA-1"})", "application/json");
  EXPECT_EQ(res->status, 401);

  // Invalid recipes are refused naming the field; the version must increase.
  nlohmann::json bad = recipe;
  bad["excitation"]["f_hi_hz"] = 10;
  res = http.Put("/api/recipe", with(kEngineer), bad.dump(), "application/json");
  EXPECT_EQ(res->status, 400);
  EXPECT_NE(res->body.find("/excitation/f_hi_hz"), std::string::npos) << res->body;
  nlohmann::json same = recipe;
  same["version"] = 1;
  res = http.Put("/api/recipe", with(kEngineer), same.dump(), "application/json");
  EXPECT_EQ(res->status, 409);
  EXPECT_NE(res->body.find("version must increase"), std::string::npos) << res->body;

  res = http.Put("/api/recipe", with(kEngineer), recipe.dump(), "application/json");
  ASSERT_EQ(res->status, 200) << res->body;
  const auto changed = nlohmann::json::parse(res->body);
  EXPECT_EQ(changed["version"], 2);
  EXPECT_EQ(changed["previous"]["hash"], old_hash);
  EXPECT_TRUE(std::filesystem::exists(dir / "pmsm-10pole.v1.json")) << "old version not kept";
  EXPECT_EQ(io::ReadJsonFile(recipe_path)["version"], 2);
  EXPECT_EQ(nlohmann::json::parse(http.Get("/api/recipe")->body)["version"], 2);

  const auto audit = nlohmann::json::parse(http.Get("/api/recipe/audit")->body)["audit"];
  ASSERT_EQ(audit.size(), 1u);
  EXPECT_EQ(audit[0]["who"], "qe-anna");
  EXPECT_EQ(audit[0]["old_hash"], old_hash);
  EXPECT_EQ(audit[0]["new_hash"], changed["hash"]);

  // The next test runs on the new recipe.
  res = http.Post("/api/tests", with(kOperator), R"({"serial": "RA-2"})", "application/json");
  ASSERT_EQ(res->status, 202) << res->body;
  nlohmann::json tests;
  eol::testing::WaitUntil(
      [&] {
        tests = nlohmann::json::parse(http.Get("/api/units/RA-2")->body)["tests"];
        return !tests.empty();
      },
      eol::testing::kGenerousDeadline, 100ms);
  ASSERT_EQ(tests.size(), 1u);
  EXPECT_EQ(tests[0]["recipe"]["version"], 2);
  EXPECT_EQ(tests[0]["recipe"]["hash"], changed["hash"]);
  station.Stop(SIGTERM, 20s);
}

}  // namespace
}  // namespace eol
