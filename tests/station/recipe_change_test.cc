// Station::ChangeRecipe as a business decision, without HTTP: each refusal is a typed
// RecipeChange that leaves the recipe file, the audit log and the recipe in use as they were;
// a change keeps the old file, audits who (with the token's role) and swaps the recipe.
// Also the token roles of the station config. Real recipe file, real SQLite store.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "drivers/io/json_config.h"
#include "station/daemon/station.h"
#include "tests/support/child_process.h"

namespace eol::station {
namespace {

using Kind = RecipeChange::Kind;

class RecipeChangeTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::filesystem::copy_file(std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json",
                               recipe_path_);
    const nlohmann::json j = {{"station_id", "rc"},
                              {"recipe", recipe_path_},
                              {"db", dir_ / "s.sqlite"},
                              {"fixture", {{"driver", "sim"}}},
                              {"daq", {{"driver", "sim"}}}};
    station_ = std::make_unique<Station>(ParseStationConfig(j, "test", ""));
    recipe_ = io::ReadJsonFile(recipe_path_);
  }

  std::string FileText() const {
    std::ifstream in(recipe_path_);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }

  eol::testing::TempDir dir_;
  const std::string recipe_path_ = dir_ / "pmsm-10pole.json";
  std::unique_ptr<Station> station_;
  nlohmann::json recipe_;
  const ApiToken anna_{"qe-anna", Role::kEngineer, "engineer-token-0123456789"};
};

TEST_F(RecipeChangeTest, RefusalsAreTypedAndChangeNothing) {
  const std::string before = FileText();
  const std::string hash = station_->recipe()->hash;

  nlohmann::json invalid = recipe_;
  invalid["version"] = 2;
  invalid["excitation"]["f_hi_hz"] = 10;
  RecipeChange r = station_->ChangeRecipe(invalid, anna_);
  EXPECT_EQ(r.kind, Kind::kInvalid);
  EXPECT_NE(r.message.find("/excitation/f_hi_hz"), std::string::npos) << r.message;

  nlohmann::json other = recipe_;
  other["version"] = 2;
  other["id"] = "another-motor";
  r = station_->ChangeRecipe(other, anna_);
  EXPECT_EQ(r.kind, Kind::kWrongRecipe);
  EXPECT_NE(r.message.find("recipe id must stay 'pmsm-10pole'"), std::string::npos) << r.message;

  r = station_->ChangeRecipe(recipe_, anna_);
  EXPECT_EQ(r.kind, Kind::kVersionNotIncreased);
  EXPECT_EQ(r.message, "version must increase: the station runs version 1, got 1");

  // The new file cannot be written: a directory stands where its temporary file goes.
  nlohmann::json next = recipe_;
  next["version"] = 2;
  std::filesystem::create_directory(recipe_path_ + ".tmp");
  r = station_->ChangeRecipe(next, anna_);
  EXPECT_EQ(r.kind, Kind::kIoError);
  EXPECT_NE(r.message.find(".tmp"), std::string::npos) << r.message;

  EXPECT_EQ(FileText(), before);
  EXPECT_EQ(station_->recipe()->hash, hash);
  EXPECT_TRUE(station_->store().AuditLog(10).empty());
}

TEST_F(RecipeChangeTest, AChangeKeepsTheOldFileAuditsAndSwaps) {
  const std::string old_hash = station_->recipe()->hash;
  nlohmann::json next = recipe_;
  next["version"] = 2;
  next["limits"][0]["lo"] = 372;
  const RecipeChange r = station_->ChangeRecipe(next, anna_);
  ASSERT_EQ(r.kind, Kind::kChanged) << r.message;
  EXPECT_EQ(r.id, "pmsm-10pole");
  EXPECT_EQ(r.version, 2);
  EXPECT_EQ(r.previous_version, 1);
  EXPECT_EQ(r.previous_hash, old_hash);
  EXPECT_EQ(r.hash, station_->recipe()->hash);
  EXPECT_NE(r.hash, old_hash);
  EXPECT_EQ(r.path, recipe_path_);
  EXPECT_EQ(r.kept_as, dir_ / "pmsm-10pole.v1.json");
  EXPECT_EQ(io::ReadJsonFile(r.kept_as)["version"], 1);
  EXPECT_EQ(io::ReadJsonFile(recipe_path_)["version"], 2);
  const auto audit = station_->store().AuditLog(10);
  ASSERT_EQ(audit.size(), 1u);
  EXPECT_EQ(audit[0].who, "qe-anna");
  EXPECT_EQ(audit[0].role, "engineer");
  EXPECT_EQ(audit[0].new_hash, r.hash);
}

TEST(TokenRoles, ParsedOnceNamingTheJsonPathAndTheAcceptedValues) {
  auto config = [](const std::string& role) {
    return nlohmann::json{
        {"recipe", "r.json"},
        {"db", "s.sqlite"},
        {"http",
         {{"tokens",
           {{{"name", "op"}, {"role", "operator"}, {"token", "operator-token-0123456789"}},
            {{"name", "x"}, {"role", role}, {"token", "another-token-0123456789"}}}}}},
        {"fixture", {{"driver", "sim"}}},
        {"daq", {{"driver", "sim"}}}};
  };
  const StationConfig c = ParseStationConfig(config("engineer"), "c.json", "");
  ASSERT_EQ(c.tokens.size(), 2u);
  EXPECT_EQ(c.tokens[0].role, Role::kOperator);
  EXPECT_EQ(c.tokens[1].role, Role::kEngineer);
  try {
    ParseStationConfig(config("Engineer"), "c.json", "");
    ADD_FAILURE() << "role 'Engineer' accepted";
  } catch (const io::ConfigError& e) {
    EXPECT_STREQ(e.what(),
                 "config c.json: /http/tokens/1/role: must be one of: operator, engineer "
                 "(got \"Engineer\")");
  }
  EXPECT_EQ(ParseRole("operator"), Role::kOperator);
  EXPECT_EQ(ParseRole("admin"), std::nullopt);
  EXPECT_STREQ(ToString(Role::kEngineer), "engineer");
}

}  // namespace
}  // namespace eol::station
