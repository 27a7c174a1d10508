// A taught recipe is a proposal until an engineer approves it (issue 12; station/daemon/recipe.h,
// RecipeApproval): eol teach writes "approval": {"state": "proposed"}; the station refuses to
// test with a proposal, at start and on PUT /api/recipe; an engineer approves it over the API
// (POST /api/recipe/approve, installed and audited under the token's name) or with
// `eol recipe-approve` (written and audited in the database); a hand-written recipe or an
// approved one cannot be approved again.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "db/store.h"
#include "db/test_record.h"
#include "drivers/io/json_config.h"
#include "station/daemon/recipe.h"
#include "tests/support/child_process.h"
#include "tests/support/eol_cli.h"
#include "tests/support/pass_records.h"
#include "tests/support/station_ready.h"
#include "tests/support/token_station.h"

// After Eigen (through station/daemon/recipe.h): <resolv.h> defines _res, a parameter name in
// Eigen.
#include <httplib.h>

namespace eol {
namespace {

using namespace std::chrono_literals;
using eol::testing::ChildProcess;
using eol::testing::PortFromReadyLine;

constexpr char kOperator[] = "operator-token-0123456789";
constexpr char kEngineer[] = "engineer-token-0123456789";
const std::string kShipped = std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json";

nlohmann::json Proposal(int version) {
  nlohmann::json r = io::ReadJsonFile(kShipped);
  r["version"] = version;
  r["approval"] = {{"state", "proposed"}, {"by", "eol teach"}, {"at", "2026-11-25T02:00:00Z"}};
  return r;
}

void WriteStationConfig(const eol::testing::TempDir& dir, const std::string& recipe) {
  nlohmann::json config = testing::TokenStationConfig("approval", recipe, kOperator, kEngineer);
  config["daq"]["time_scale"] = 0.0;
  std::ofstream(dir / "station.json") << config.dump();
}

httplib::Headers With(const char* token) {
  return httplib::Headers{{"Authorization", std::string("Bearer ") + token}};
}

TEST(RecipeApproval, ParsedNamingTheFieldAndWrittenBack) {
  nlohmann::json r = Proposal(2);
  const station::Recipe p = station::ParseRecipe(r, "proposal");
  ASSERT_TRUE(p.approval.has_value());
  EXPECT_FALSE(p.Approved());
  EXPECT_NE(p.WhyNotApproved().find("is a proposal (eol teach"), std::string::npos);
  EXPECT_EQ(station::ParseRecipe(station::RecipeToJson(p), "again").approval, p.approval);
  EXPECT_TRUE(station::ParseRecipe(io::ReadJsonFile(kShipped), "shipped").Approved());
  r["approval"]["state"] = "maybe";
  try {
    station::ParseRecipe(r, "bad");
    ADD_FAILURE() << "a state other than proposed/approved was accepted";
  } catch (const io::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/approval/state"), std::string::npos) << e.what();
  }
  r = Proposal(2);
  r["approval"].erase("by");
  EXPECT_THROW(station::ParseRecipe(r, "no by"), io::ConfigError);
}

TEST(RecipeApproval, StationRefusesProposalsUntilAnEngineerApprovesOverTheApi) {
  eol::testing::TempDir dir;
  std::ofstream(dir / "r.json") << Proposal(2).dump(2);
  WriteStationConfig(dir, "r.json");
  ChildProcess station({EOL_BINARY, "station", "--config", dir / "station.json"});
  ASSERT_TRUE(station.WaitFor([](const std::string& o) { return PortFromReadyLine(o) > 0; }, 30s))
      << station.output();
  httplib::Client http("127.0.0.1", PortFromReadyLine(station.output()));

  // Started with a proposal: no test runs, and the status says why.
  auto res = http.Post("/api/tests", With(kOperator), R"({"serial": "AP-1"})", "application/json");
  ASSERT_TRUE(res);
  EXPECT_NE(res->status, 202) << res->body;
  EXPECT_NE(res->body.find("proposal"), std::string::npos) << res->body;

  // PUT refuses a proposal; only engineers approve; only proposals are approved.
  res = http.Put("/api/recipe", With(kEngineer), Proposal(3).dump(), "application/json");
  EXPECT_EQ(res->status, 409) << res->body;
  EXPECT_NE(res->body.find("recipe_not_approved"), std::string::npos) << res->body;
  const nlohmann::json approve = {{"recipe", Proposal(3)}, {"note", "population run 12"}};
  res = http.Post("/api/recipe/approve", With(kOperator), approve.dump(), "application/json");
  EXPECT_EQ(res->status, 403) << res->body;
  res =
      http.Post("/api/recipe/approve", With(kEngineer),
                nlohmann::json{{"recipe", io::ReadJsonFile(kShipped)}}.dump(), "application/json");
  EXPECT_EQ(res->status, 400) << res->body;
  EXPECT_NE(res->body.find("only a proposal is approved"), std::string::npos) << res->body;

  res = http.Post("/api/recipe/approve", With(kEngineer), approve.dump(), "application/json");
  ASSERT_EQ(res->status, 200) << res->body;
  const auto in_use = nlohmann::json::parse(http.Get("/api/recipe")->body);
  EXPECT_EQ(in_use["version"], 3) << in_use.dump();
  const auto audit = nlohmann::json::parse(http.Get("/api/recipe/audit")->body)["audit"];
  ASSERT_EQ(audit.size(), 1u);
  EXPECT_EQ(audit[0]["who"], "qe-anna");
  const nlohmann::json file = io::ReadJsonFile(dir / "r.json");
  EXPECT_EQ(file["approval"]["state"], "approved");
  EXPECT_EQ(file["approval"]["by"], "qe-anna");
  EXPECT_EQ(file["approval"]["note"], "population run 12");

  // Now tests run.
  res = http.Post("/api/tests", With(kOperator), R"({"serial": "AP-2"})", "application/json");
  EXPECT_EQ(res->status, 202) << res->body;
  station.Stop(SIGTERM, 20s);
}

TEST(RecipeApproval, TaughtRecipeIsAProposalApprovedOnTheCommandLine) {
  eol::testing::TempDir dir;
  // Ten PASS records of the shipped recipe, as `eol export --format records` writes them.
  const std::string hash = station::LoadRecipe(kShipped).hash;
  const nlohmann::json list = testing::PassRecords(hash, 10);
  std::ofstream(dir / "records.json") << list.dump(1);
  const std::string taught = dir / "taught.json";
  auto r = testing::RunEol({"teach", "--recipe", kShipped, "--out", taught, "--allow-few-units",
                            "--golden", dir / "records.json"},
                           true, 120s);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(io::ReadJsonFile(taught)["approval"]["state"], "proposed");
  EXPECT_FALSE(station::LoadRecipe(taught).Approved());

  const std::string db = dir / "s.sqlite";
  db::Store::Open(db);  // the station's database (created here)
  r = testing::RunEol({"recipe-approve", "--recipe", taught, "--by", "qe-anna", "--note",
                       "reviewed the teach report", "--db", db},
                      true, 60s);
  ASSERT_EQ(r.code, 0) << r.out;
  const station::Recipe approved = station::LoadRecipe(taught);
  ASSERT_TRUE(approved.Approved());
  EXPECT_EQ(approved.approval->by, "qe-anna");
  EXPECT_EQ(approved.approval->note, "reviewed the teach report");
  const auto audit = db::Store::Open(db)->AuditLog();
  ASSERT_EQ(audit.size(), 1u);
  EXPECT_EQ(audit[0].who, "qe-anna");
  EXPECT_EQ(audit[0].new_hash, approved.hash);
  EXPECT_NE(audit[0].old_hash, approved.hash);

  // Nothing to approve twice, nor a hand-written recipe.
  r = testing::RunEol({"recipe-approve", "--recipe", taught, "--by", "qe-anna", "--db", db}, true,
                      60s);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("not a proposal"), std::string::npos) << r.out;
  EXPECT_EQ(db::Store::Open(db)->AuditLog().size(), 1u);
}

}  // namespace
}  // namespace eol
